// Character controller: input becomes root motion (forward, back, turn, walk or run), the
// character never leaves the pit, and gravity never touches it.
#include <gtest/gtest.h>

#include <cmath>

#include "systems/character_controller.h"
#include "tests/character_fixture.h"

namespace ballpit {
namespace {

using test::CharacterSim;

constexpr float kPi = 3.14159265f;

TEST(CharacterController, ForwardInputWalksAlongTheHeadingAtWalkSpeed) {
  CharacterSim sim;
  sim.start();
  sim.mut_motion().input = {1.0f, 0.0f, false};
  sim.step(120);
  const float walk = sim.setup().controller.walk_speed;
  EXPECT_EQ(walk, sim.setup().gaits[kWalk].speed);  // the walk clip's own speed by default
  EXPECT_FLOAT_EQ(sim.motion().current.speed, walk);
  const Vec3 before = sim.motion().current.position;
  sim.step(60);
  const Vec3 moved = sim.motion().current.position - before;
  // Heading 0 faces +z: one second at walk speed, all of it along z (float sums of 60 steps).
  EXPECT_NEAR(moved.z(), walk, 1e-4f);
  EXPECT_NEAR(moved.x(), 0.0f, 1e-6f);
  EXPECT_EQ(moved.y(), 0.0f);
}

TEST(CharacterController, BackwardInputWalksBackwardAndRunReachesRunSpeed) {
  CharacterSim sim;
  sim.start();
  sim.mut_motion().input = {-1.0f, 0.0f, false};
  sim.step(120);
  EXPECT_FLOAT_EQ(sim.motion().current.speed, -sim.setup().controller.back_speed);
  EXPECT_LT(sim.motion().current.position.z(), 0.0f);
  sim.mut_motion().input = {1.0f, 0.0f, true};
  sim.step(240);
  EXPECT_FLOAT_EQ(sim.motion().current.speed, sim.setup().gaits[kRun].speed);
  EXPECT_EQ(sim.pose().weights[kRun], 1.0f);
}

TEST(CharacterController, TurnLeftTurnsCounterClockwiseSeenFromAbove) {
  CharacterSim sim;
  sim.start();
  sim.mut_motion().input = {0.0f, 1.0f, false};
  sim.step(30);  // half a second at 90 degrees a second
  EXPECT_NEAR(sim.motion().current.heading, 0.25f * kPi, 1e-5f);
  // Facing +z with y up, left is +x: walking now drifts toward +x.
  sim.mut_motion().input = {1.0f, 0.0f, false};
  sim.step(120);
  EXPECT_GT(sim.motion().current.position.x(), 0.1f);
  sim.mut_motion().input = {0.0f, -1.0f, false};
  sim.step(30);
  EXPECT_NEAR(sim.motion().current.heading, 0.0f, 1e-5f);
}

TEST(CharacterController, TheCharacterNeverLeavesThePit) {
  // A pit 1.5 m wider than the footprint: run into a wall, turn along it, run into the corner.
  CharacterSim sim;
  const float half = sim.setup().footprint_radius + sim.setup().controller.wall_clearance + 0.75f;
  sim.world.pit.half_width = half;
  sim.start();
  sim.mut_motion().script = {{4.0f, {1.0f, 0.0f, true}}, {1.0f, {1.0f, 1.0f, true}}, {4.0f, {1.0f, 0.0f, true}},
                             {3.0f, {1.0f, -1.0f, false}}};
  float widest = 0.0f, furthest = 0.0f;
  for (int i = 0; i < 12 * 60; ++i) {
    sim.step();
    const Vec3& root = sim.motion().current.position;
    furthest = std::max({furthest, std::abs(root.x()), std::abs(root.z())});
    const ColliderTable& c = sim.world.colliders;
    const float dt = sim.world.step();
    for (std::size_t k = 0; k < c.size(); ++k)
      for (const Vec3& e : {Vec3(c.a()[k] + c.velocity_a()[k] * dt), Vec3(c.b()[k] + c.velocity_b()[k] * dt)})
        widest = std::max({widest, std::abs(e.x()) + c.radius()[k], std::abs(e.z()) + c.radius()[k]});
  }
  // Every collider surface stays inside the walls by the clearance (float rounding 1e-5 m).
  EXPECT_LE(widest, half - sim.setup().controller.wall_clearance + 1e-5f);
  // And it did get to the walls: the root reached its limit.
  EXPECT_FLOAT_EQ(furthest, root_limit(sim.setup(), sim.world.pit));
}

TEST(CharacterController, ATooSmallPitKeepsTheCharacterCentred) {
  CharacterSim sim(CharacterDesc::wuson(), 1.0f);
  sim.start();
  sim.mut_motion().input = {1.0f, 0.0f, true};
  sim.step(120);
  EXPECT_EQ(sim.motion().current.position.x(), 0.0f);
  EXPECT_EQ(sim.motion().current.position.z(), 0.0f);
  EXPECT_GT(sim.motion().current.speed, 1.0f);  // it still runs, in place
}

TEST(CharacterController, GravityNeverMovesTheCharacter) {
  // The same script under changing gravity (the app ties it to the camera) and under none:
  // the character's path is identical, bit for bit, and it never leaves its height.
  auto run = [](bool tumble) {
    CharacterDesc desc = CharacterDesc::wuson();
    desc.position = Vec3(0.0f, 0.3f, 0.0f);
    CharacterSim sim(desc);
    sim.start();
    sim.mut_motion().script = {{2.0f, {1.0f, 0.5f, false}}, {2.0f, {1.0f, -0.5f, true}}};
    std::vector<Vec3> path;
    for (int i = 0; i < 240; ++i) {
      if (tumble) sim.world.set_gravity(Vec3(std::sin(0.1f * i), -9.81f * std::cos(0.05f * i), 3.0f));
      sim.step();
      path.push_back(sim.motion().current.position);
      EXPECT_EQ(sim.motion().current.position.y(), 0.3f);
    }
    return path;
  };
  const auto calm = run(false), tumbling = run(true);
  for (std::size_t i = 0; i < calm.size(); ++i) EXPECT_TRUE(calm[i] == tumbling[i]) << "step " << i;
}

TEST(CharacterController, TheScriptGivesEachSegmentsInputInTurn) {
  const std::vector<ScriptSegment> script = {{3.0f, {1.0f, 0.0f, false}}, {2.0f, {1.0f, 1.0f, false}},
                                             {3.0f, {1.0f, 0.0f, true}}};
  EXPECT_EQ(scripted_input(script, 0.0f).turn, 0.0f);
  EXPECT_EQ(scripted_input(script, 2.99f).run, false);
  EXPECT_EQ(scripted_input(script, 3.0f).turn, 1.0f);
  EXPECT_EQ(scripted_input(script, 5.5f).run, true);
  EXPECT_EQ(scripted_input(script, 8.0f).forward, 0.0f);  // after the end: no input, idle
}

TEST(CharacterController, BlendsTakeAtLeastTheBlendTime) {
  // Idle to walk: the walk is slow, so the acceleration cap (walk speed / blend time) decides.
  CharacterSim sim;
  sim.start();
  sim.mut_motion().input = {1.0f, 0.0f, false};
  int steps = 0;
  while (sim.pose().weights[kWalk] < 1.0f && steps < 600) {
    sim.step();
    ++steps;
  }
  EXPECT_GE(static_cast<float>(steps) / 60.0f, sim.setup().controller.blend_time - 1e-3f);
}

}  // namespace
}  // namespace ballpit
