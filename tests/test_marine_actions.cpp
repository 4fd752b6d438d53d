// The marine played as a character: jump and kick start from the input and fade in and out
// over the locomotion, the jump leaves the ground and the kick swings the right foot through,
// and going idle -> walk -> run -> walk -> idle, jumping and kicking on the way, no joint pops
// between 60 Hz frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "engine/marine/marine.h"
#include "engine/marine/marine_skeleton.h"
#include "tests/character_fixture.h"
#include "systems/animation.h"

namespace ballpit {
namespace {

struct MarineSim {
  World world;
  Scheduler scheduler{1};
  std::unique_ptr<FixedStepLoop> loop;

  MarineSim() {
    world.pit.half_width = 50.0f;
    add_character(world, marine::marine_model(), CharacterDesc{});
    add_character_systems(scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, scheduler);
  }
  CharacterMotion& motion() { return world.characters.mut_motion(0); }
  const CharacterPose& pose() const { return world.characters.pose(0); }
  // World positions of every joint at the end of the last step (unit: m).
  std::vector<Vec3> joints() const {
    const CharacterSetup& setup = world.characters.setup(0);
    const Affine3 w = character_transform(setup, world.characters.motion(0).current);
    std::vector<Vec3> out;
    for (const Affine3& m : pose().model) out.push_back(w * m.translation());
    return out;
  }
};

TEST(MarineActions, TheMarineHasBothActionsAndTheWusonNone) {
  MarineSim sim;
  const CharacterSetup& s = sim.world.characters.setup(0);
  EXPECT_EQ(s.model->clips[static_cast<std::size_t>(s.actions[kJump])].name, marine::kJumpClip);
  EXPECT_EQ(s.model->clips[static_cast<std::size_t>(s.actions[kKick])].name, marine::kKickClip);
  test::CharacterSim wuson;
  EXPECT_EQ(wuson.setup().actions[kJump], -1);
  EXPECT_EQ(wuson.setup().actions[kKick], -1);
  wuson.start();
  wuson.mut_motion().input.jump = true;  // a model without the clip ignores the request
  wuson.step(5);
  EXPECT_EQ(wuson.pose().action, -1);
}

TEST(MarineActions, AnActionFadesInAndOut) {
  EXPECT_EQ(action_weight(0.0f, 1.0f), 0.0f);
  EXPECT_EQ(action_weight(0.5f, 1.0f), 1.0f);
  EXPECT_EQ(action_weight(1.0f, 1.0f), 0.0f);
  EXPECT_NEAR(action_weight(0.5f * kActionFade, 1.0f), 0.5f, 1e-6f);
  EXPECT_LT(action_weight(0.1f, 0.2f), 1.0f);  // shorter than two fades: never at full weight
}

TEST(MarineActions, TheJumpLeavesTheGroundAndLandsWhereItStarted) {
  MarineSim sim;
  sim.loop->step();
  const float standing = std::min(sim.joints()[marine::kLeftToeBase].y(), sim.joints()[marine::kRightToeBase].y());
  sim.motion().input.jump = true;
  sim.loop->step();
  sim.motion().input.jump = false;
  ASSERT_EQ(sim.pose().action, kJump);
  float highest_feet = standing;
  int steps = 0;
  while (sim.pose().action == kJump && steps < 300) {
    sim.loop->step();
    ++steps;
    const auto j = sim.joints();
    highest_feet = std::max(highest_feet, std::min(j[marine::kLeftToeBase].y(), j[marine::kRightToeBase].y()));
  }
  std::printf("[ jump ] %d steps; both feet up to %.3f m above standing\n", steps, highest_feet - standing);
  EXPECT_EQ(sim.pose().action, -1);
  EXPECT_GT(highest_feet - standing, 0.15f);  // a 0.5 s flight rises 0.31 m at the hips
  sim.loop->step();
  const auto j = sim.joints();
  EXPECT_NEAR(std::min(j[marine::kLeftToeBase].y(), j[marine::kRightToeBase].y()), standing, 0.005f);
}

TEST(MarineActions, TheKickSwingsTheRightFootThroughFast) {
  MarineSim sim;
  sim.loop->step();
  sim.motion().input.kick = true;
  sim.loop->step();
  sim.motion().input.kick = false;
  ASSERT_EQ(sim.pose().action, kKick);
  std::vector<Vec3> before = sim.joints();
  float fastest_right = 0.0f, fastest_left = 0.0f, reach = 0.0f;
  while (sim.pose().action == kKick) {
    sim.loop->step();
    const auto now = sim.joints();
    fastest_right = std::max(fastest_right, (now[marine::kRightToeBase] - before[marine::kRightToeBase]).norm() * 60.0f);
    fastest_left = std::max(fastest_left, (now[marine::kLeftToeBase] - before[marine::kLeftToeBase]).norm() * 60.0f);
    reach = std::max(reach, now[marine::kRightToeBase].z() - now[marine::kHips].z());
    before = now;
  }
  std::printf("[ kick ] right foot up to %.2f m/s, %.2f m in front of the hips; left foot %.3f m/s\n", fastest_right,
              reach, fastest_left);
  EXPECT_GT(fastest_right, 5.0f);
  EXPECT_GT(reach, 0.4f);
  EXPECT_LT(fastest_left, 0.05f);  // the standing foot stays planted
}

TEST(MarineActions, NoJointPopsThroughEveryBlendAndAction) {
  // idle 1 s, walk 2 s, run 2 s, walk 2 s, idle 1 s, then jump and kick from a walk, and a
  // jump from a run: the whole repertoire, every change of blend.
  MarineSim sim;
  struct Segment {
    int steps;
    ControllerInput input;
  };
  const std::vector<Segment> script = {
      {60, {}},
      {120, {1.0f, 0.0f, false}},
      {120, {1.0f, 0.0f, true}},
      {120, {1.0f, 0.0f, false}},
      {60, {}},
      {1, {0.0f, 0.0f, false, true, false}},
      {120, {}},
      {60, {1.0f, 0.0f, false}},
      {1, {1.0f, 0.0f, false, false, true}},
      {90, {1.0f, 0.0f, false}},
      {60, {1.0f, 0.0f, true}},
      {1, {1.0f, 0.0f, true, true, false}},
      {120, {1.0f, 0.0f, true}},
      {90, {}},
  };
  sim.loop->step();
  std::vector<Vec3> previous = sim.joints(), before_previous = previous;
  // The bound: a pop is a joint jumping far beyond what its neighbours in time show. The
  // fastest motions the clips hold are a running foot's swing (twice the 3.5 m/s ground speed)
  // and the kick's foot (8 m/s); a jump fading in over a run adds its pose change (about 0.6 m
  // over the 0.2 s fade) to the first. So per 60 Hz frame: displacement under 15 m/s x dt
  // (measured 12.3), and the change of displacement (acceleration x dt^2) under 400 m/s^2 x
  // dt^2 (the kick reverses an 8 m/s foot in about 0.04 s; measured 286). A pose that jumped by
  // even 10 cm in one frame would show as 6 m/s more and 2,000 m/s^2.
  constexpr float kFastest = 15.0f, kHardest = 400.0f, dt = 1.0f / 60.0f;
  float fastest = 0.0f, hardest = 0.0f;
  int frame = 0;
  for (const Segment& seg : script) {
    for (int k = 0; k < seg.steps; ++k, ++frame) {
      sim.motion().input = seg.input;
      sim.loop->step();
      const auto now = sim.joints();
      for (std::size_t j = 0; j < now.size(); ++j) {
        fastest = std::max(fastest, (now[j] - previous[j]).norm() / dt);
        if (frame > 0) hardest = std::max(hardest, (now[j] - 2.0f * previous[j] + before_previous[j]).norm() / (dt * dt));
      }
      before_previous = previous;
      previous = now;
    }
  }
  std::printf("[ blends ] fastest joint %.2f m/s, hardest %.1f m/s^2 over %d frames\n", fastest, hardest, frame);
  EXPECT_LT(fastest, kFastest);
  EXPECT_LT(hardest, kHardest);
}

}  // namespace
}  // namespace ballpit
