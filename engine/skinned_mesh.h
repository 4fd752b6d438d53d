// A skinned mesh: vertices in the model's bind space with up to four joint influences each
// (weights normalised to sum to 1), triangles, and the inverse bind matrix of every bone it
// uses. Skinned position = sum_k weight_k * (joint model transform * inverse bind) * vertex.
// Decision: inverse bind matrices are kept per mesh (a bone may sit in several meshes with
// different bind spaces); influences index the mesh's own bone list, as a GPU palette does.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/math.h"
#include "engine/texture.h"

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

  // How it looks, as far as the file says; each part is optional and they multiply, as glTF's
  // base colour does: base_color x vertex colour x texture at the vertex's coordinates.
  Vec4 base_color = Vec4::Ones();                      // the material's, linear RGBA
  std::vector<std::array<std::uint8_t, 4>> colors;     // per vertex, sRGB RGB + alpha; empty: none
  std::vector<Vec2> uvs;  // per vertex, (0, 0) the image's top-left texel as glTF has it; empty: none
  std::shared_ptr<const Texture> base_color_texture;   // null: none
};

}  // namespace ballpit
