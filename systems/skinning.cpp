#include "systems/skinning.h"

#include "engine/world.h"

namespace ballpit {

void skinning_palette(const SkinnedMesh& mesh, const std::vector<Affine3>& model, const Affine3& world,
                      std::vector<Mat4>& palette) {
  palette.resize(mesh.bone_joint.size());
  for (std::size_t k = 0; k < mesh.bone_joint.size(); ++k)
    palette[k] = (world * model[mesh.bone_joint[k]] * mesh.inverse_bind[k]).matrix();
}

void skin_positions(const SkinnedMesh& mesh, std::span<const Mat4> palette, std::vector<Vec3>& out) {
  const std::size_t n = mesh.positions.size();
  out.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const Vec4 p = mesh.positions[v].homogeneous();
    Vec4 sum = Vec4::Zero();
    for (int k = 0; k < kMaxInfluences; ++k) {
      const float w = mesh.weights[v][k];
      if (w == 0.0f) continue;
      sum += w * (palette[mesh.bones[v][k]] * p);
    }
    out[v] = sum.head<3>();
  }
}

Access SkinningSystem::access() const {
  Access a;
  a.reads = {ColumnId::CharacterController, ColumnId::CharacterPose};
  a.writes = {ColumnId::CharacterPose};
  return a;
}

void SkinningSystem::run(World& world) {
  CharacterTable& characters = world.characters;
  for (std::size_t i = 0; i < characters.size(); ++i) {
    const CharacterSetup& setup = characters.setup(i);
    const Affine3 w = character_transform(setup, characters.motion(i).current);
    CharacterPose& pose = characters.mut_pose(i);
    const std::vector<SkinnedMesh>& meshes = setup.model->meshes;
    pose.palettes.resize(meshes.size());
    for (std::size_t m = 0; m < meshes.size(); ++m) skinning_palette(meshes[m], pose.model, w, pose.palettes[m]);
  }
}

}  // namespace ballpit
