// Model import through assimp: a file becomes a Model (skeleton with inverse bind matrices,
// skinned meshes with at most four normalised weights per vertex, clips with keys in seconds).
// Reads: the file. Writes: nothing else.
// Decision: anything the engine cannot animate is an error at import, not a crash later: a
// missing or unreadable file, no mesh with bones (no skeleton), or no clips each throw
// ballpit::Error naming the file and what is missing.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/marine/marine.h"
#include "engine/model.h"

namespace ballpit {

// Debian's assimp-testmodels package installs the second model, the Wuson, here.
inline constexpr const char* kWusonModelPath = "/usr/share/assimp/models/X/Testwuson.X";
// The default character: the project's own marine (engine/marine/marine.h), built in code.
inline constexpr const char* kDefaultModelPath = marine::kModelName;

// How import_model reads a file.
struct ModelImportOptions {
  // A file without clips is refused, unless the scene brings every clip from other files
  // (engine/clip_sources.h: Mixamo's character file holds no animation).
  bool require_clips = true;
};

std::shared_ptr<const Model> import_model(const std::string& path, const ModelImportOptions& options = {});

// One animation of a file, its channels by node name, not yet matched to a skeleton
// (engine/clip_sources.h matches them by joint name).
struct FileClip {
  std::string name;
  float duration = 0.0f;          // (unit: s)
  float ticks_per_second = 0.0f;  // the file's time base
  std::vector<std::string> nodes;  // channel k animates the node named nodes[k]
  std::vector<JointTrack> tracks;  // channel k's keys (unit: s); a kind the file does not key is empty
};

// The animations of a file, read through the model probe as import_model reads. The file needs
// no mesh and no bones: a clip file may hold only a skeleton and its animation. Throws
// ballpit::Error naming the file if it cannot be read or has no animation.
std::vector<FileClip> import_clips(const std::string& path);

// A character's model by the name a scene gives it: "builtin:marine" is the marine made in
// code, shared by every user; anything else is a file for import_model.
std::shared_ptr<const Model> load_model(const std::string& path);
// Whether a model name is a built-in one (no file to look for).
bool is_builtin_model(const std::string& path);

}  // namespace ballpit
