// An imported model: skeleton, skinned meshes and clips, immutable once loaded and shared by
// every character that uses it. Lengths are in the file's units; a character scales them.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/clip.h"
#include "engine/math.h"
#include "engine/skeleton.h"
#include "engine/skinned_mesh.h"

namespace ballpit {

struct Model {
  std::string path;  // the file it came from, for messages
  // The name load_model rebuilds it from, where that is not `path`: a model assembled from clip
  // sources (engine/clip_sources.h). Snapshots name the model by it.
  std::string load_name;
  Skeleton skeleton;
  std::vector<SkinnedMesh> meshes;
  std::vector<Clip> clips;
  // Bounds of the bind-pose vertices of all meshes (unit: model units).
  Vec3 bind_min = Vec3::Zero();
  Vec3 bind_max = Vec3::Zero();

  float bind_height() const { return bind_max.y() - bind_min.y(); }
  std::size_t vertex_count() const;
  // Index of a clip; throws ballpit::Error naming the file, the clip and the clips it has.
  std::size_t clip_index(std::string_view name) const;
};

}  // namespace ballpit
