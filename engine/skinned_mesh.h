// A skinned mesh: vertices in the model's bind space with up to four joint influences each
// (weights normalised to sum to 1), triangles, and the inverse bind matrix of every bone it
// uses. Skinned position = sum_k weight_k * (joint model transform * inverse bind) * vertex.
// Decision: inverse bind matrices are kept per mesh (a bone may sit in several meshes with
// different bind spaces); influences index the mesh's own bone list, as a GPU palette does.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/math.h"

namespace ballpit {

inline constexpr int kMaxInfluences = 4;

struct SkinnedMesh {
  std::string name;
  std::vector<Vec3> positions;  // bind pose (unit: model units)
  std::vector<Vec3> normals;    // bind pose, unit length
  std::vector<std::uint32_t> indices;  // triangles, three per face
  // Per vertex: mesh bone indices and weights; unused slots have weight 0 and bone 0.
  std::vector<std::array<std::uint16_t, kMaxInfluences>> bones;
  std::vector<std::array<float, kMaxInfluences>> weights;
  // Per mesh bone: its skeleton joint and inverse bind matrix (mesh space -> joint space).
  std::vector<std::uint16_t> bone_joint;
  std::vector<Affine3> inverse_bind;
};

}  // namespace ballpit
