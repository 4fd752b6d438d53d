// Model import through assimp: a file becomes a Model (skeleton with inverse bind matrices,
// skinned meshes with at most four normalised weights per vertex, clips with keys in seconds).
// Reads: the file. Writes: nothing else.
// Decision: anything the engine cannot animate is an error at import, not a crash later: a
// missing or unreadable file, no mesh with bones (no skeleton), or no clips each throw
// ballpit::Error naming the file and what is missing.
#pragma once

#include <memory>
#include <string>

#include "engine/model.h"

namespace ballpit {

// Debian's assimp-testmodels package installs the default character here.
inline constexpr const char* kDefaultModelPath = "/usr/share/assimp/models/X/Testwuson.X";

std::shared_ptr<const Model> import_model(const std::string& path);

}  // namespace ballpit
