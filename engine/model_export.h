// Model export to glTF 2.0 through assimp: a Model (the marine made in code, or one imported)
// becomes a file other tools open: the skeleton as nodes with their rest TRS, each skinned mesh
// with positions, normals, vertex colours, texture coordinates, its bones' inverse bind matrices
// and weights, a material with the base colour and texture, and every clip as an animation.
// Reads: the model. Writes: the file, atomically (engine/atomic_file.h): a failed export leaves
// the previous file, if any, untouched, and throws ballpit::Error naming the path and why.
// Decision: what glTF cannot say is carried so that import_model reads the same model back:
// a clip's duration is the time of its latest key in glTF, so each clip gets a "clock" channel
// on the first mesh's node (not a joint, so import ignores its keys) keyed at 0 and the duration;
// the joints' own keys are written as they are. The meshes' nodes sit under a root node at the
// origin: a plain "root" above the root joints unless the skeleton's one root is already such a
// node (import then reads one more joint, at identity: no vertex moves). Not carried: a clip's
// looping flag and time base (glTF has neither; import reads every clip as looping, at assimp's
// 1000 ticks a second). A base colour texture is embedded as a PNG.
#pragma once

#include <string>

#include "engine/model.h"

namespace ballpit {

// Writes the model as binary glTF (".glb") or as JSON glTF with its buffer beside it (".gltf":
// FILE.gltf and FILE.bin, each replaced whole, the .bin first; the pair is not replaced as one).
// Any other extension is refused. Throws ballpit::Error naming the path.
void export_model_gltf(const Model& model, const std::string& path);

}  // namespace ballpit
