// A skeleton: the joint hierarchy an imported model animates, as arrays indexed by joint.
// Joints are stored parents first (parents[j] < j), so local-to-model is one forward pass.
// Decision: a joint is every node that skins vertices (a "bone") plus its ancestors; mesh nodes
// and their transforms are not joints (skinning must not apply a mesh node's transform).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/math.h"

namespace ballpit {

struct Skeleton {
  std::vector<std::string> names;        // the model file's node names
  std::vector<std::int32_t> parents;     // parent joint, -1 for a root
  // The node's own transform in the file: the rest pose, used by a joint no clip animates.
  std::vector<Vec3> rest_translation;    // (unit: model units)
  std::vector<Quat> rest_rotation;
  std::vector<Vec3> rest_scale;
  std::vector<std::uint8_t> is_bone;     // 1 if some mesh vertex is weighted to this joint

  std::size_t size() const { return names.size(); }
  std::size_t bone_count() const;
  // Joint index of a node name, -1 if the skeleton has no such joint.
  int find(std::string_view name) const;
};

}  // namespace ballpit
