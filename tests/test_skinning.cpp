// Skinning: the palette maps bind space straight to the world (the mesh node's transform is
// not applied on top), so the bind pose skins every vertex to itself and a placed character's
// vertices follow its transform.
#include <gtest/gtest.h>

#include <cmath>

#include "systems/clip_sampling.h"
#include "systems/skinning.h"
#include "tests/character_fixture.h"

namespace ballpit {
namespace {

using test::CharacterSim;
using test::epileptic;
using test::wuson;

// Bind pose: joint model transform x inverse bind is the identity up to the float rounding of
// a few 4x4 products of unit-scale matrices: 1e-5 model units (10 micrometres at 1.8 m).
constexpr float kBindTolerance = 1e-5f;

float bind_pose_error(const Model& m) {
  LocalPose rest;
  rest_pose(m.skeleton, rest);
  std::vector<Affine3> model;
  local_to_model(m.skeleton, rest, model);
  std::vector<Mat4> palette;
  std::vector<Vec3> skinned;
  float worst = 0.0f;
  for (const SkinnedMesh& mesh : m.meshes) {
    skinning_palette(mesh, model, Affine3::Identity(), palette);
    skin_positions(mesh, palette, skinned);
    for (std::size_t v = 0; v < skinned.size(); ++v) worst = std::max(worst, (skinned[v] - mesh.positions[v]).norm());
  }
  return worst;
}

TEST(Skinning, TheBindPoseSkinsEveryVertexToItself) {
  EXPECT_LT(bind_pose_error(*wuson()), kBindTolerance);
  EXPECT_LT(bind_pose_error(*epileptic()), kBindTolerance);
}

TEST(Skinning, TheWusonStandsUprightBecauseTheMeshNodeRotationIsNotApplied) {
  // The Wuson's mesh node turns -90 degrees about x; applied on top it would lie on its side
  // (3.2 units tall, 1.5 long). Skinned, it is 1.515 tall along y and 3.2 long along z.
  const Model& m = *wuson();
  LocalPose rest;
  rest_pose(m.skeleton, rest);
  std::vector<Affine3> model;
  local_to_model(m.skeleton, rest, model);
  std::vector<Mat4> palette;
  std::vector<Vec3> skinned;
  skinning_palette(m.meshes[0], model, Affine3::Identity(), palette);
  skin_positions(m.meshes[0], palette, skinned);
  Vec3 lo = Vec3::Constant(1e9f), hi = Vec3::Constant(-1e9f);
  for (const Vec3& p : skinned) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  EXPECT_NEAR(hi.y() - lo.y(), 1.515f, 1e-3f);
  EXPECT_NEAR(hi.z() - lo.z(), 3.244f, 1e-3f);
}

TEST(Skinning, ThePaletteCarriesTheCharacterIntoTheWorld) {
  // A character standing at (1, 0.2, -2) turned 90 degrees left, in its idle (bind) pose: its
  // skinned vertices are the bind vertices moved by its world transform.
  CharacterDesc desc = CharacterDesc::wuson();
  desc.position = Vec3(1.0f, 0.2f, -2.0f);
  desc.heading = 1.5707963f;
  CharacterSim sim(desc);
  sim.start();
  sim.step();  // the skinning system writes the palette
  const Model& m = *wuson();
  const Affine3 w = character_transform(sim.setup(), sim.motion().current);
  ASSERT_EQ(sim.pose().palettes.size(), m.meshes.size());
  std::vector<Vec3> skinned;
  skin_positions(m.meshes[0], sim.pose().palettes[0], skinned);
  float worst = 0.0f;
  for (std::size_t v = 0; v < skinned.size(); ++v) worst = std::max(worst, (skinned[v] - w * m.meshes[0].positions[v]).norm());
  EXPECT_LT(worst, 1e-4f);  // 1e-5 model units of bind-pose rounding, scaled by 1.19 and moved 2 m
  // Facing +x now: the head end (largest bind z) is the largest world x.
  float head_x = -1e9f;
  for (const Vec3& p : skinned) head_x = std::max(head_x, p.x());
  EXPECT_NEAR(head_x, 1.0f + sim.setup().scale * m.bind_max.z(), 1e-3f);
}

TEST(Skinning, AVertexWithOneBoneMovesRigidlyWithIt) {
  // Any pose: a vertex weighted 1 to a bone is that bone's palette matrix times its bind
  // position, exactly as the renderer computes it.
  const Model& m = *wuson();
  ClipCursor cursor;
  cursor.reset(m.skeleton.size());
  LocalPose pose;
  sample_clip(m.clips[m.clip_index("Wuson_Run")], 0.3f, cursor, pose);
  std::vector<Affine3> model;
  local_to_model(m.skeleton, pose, model);
  std::vector<Mat4> palette;
  std::vector<Vec3> skinned;
  const SkinnedMesh& mesh = m.meshes[0];
  skinning_palette(mesh, model, Affine3::Identity(), palette);
  skin_positions(mesh, palette, skinned);
  int checked = 0;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (mesh.weights[v][0] != 1.0f) continue;
    const std::uint16_t bone = mesh.bones[v][0];
    const Vec3 expected = model[mesh.bone_joint[bone]] * (mesh.inverse_bind[bone] * mesh.positions[v]);
    EXPECT_LT((skinned[v] - expected).norm(), 1e-5f);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace ballpit
