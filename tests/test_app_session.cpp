// The app's session: interpolation between steps (the previous position of every sphere, by
// entity, though rows are re-sorted each step), pouring, reset, the collider kind switch, and
// key presses steering the character. No OpenGL.
#include <gtest/gtest.h>

#include <unordered_map>

#include "app/camera.h"
#include "app/controls.h"
#include "app/session.h"
#include "engine/error.h"
#include "engine/state_hash.h"
#include "engine/world.h"

using namespace ballpit;

namespace {

SessionOptions pour(std::size_t n) {
  SessionOptions o;
  o.scene = "pour";
  o.spheres = n;
  o.threads = 2;
  return o;
}

SessionOptions play(std::size_t n) {
  SessionOptions o;
  o.scene = "play";
  o.spheres = n;
  o.threads = 2;
  return o;
}

std::unordered_map<std::uint32_t, Vec3> positions_by_entity(const World& w) {
  std::unordered_map<std::uint32_t, Vec3> out;
  for (std::size_t i = 0; i < w.spheres.size(); ++i) out[w.spheres.entity_index()[i]] = w.spheres.position()[i];
  return out;
}

constexpr double kStep = 1.0 / 60.0;  // (unit: s)

}  // namespace

TEST(Session, InterpolationStartsFromEverySpheresPositionBeforeTheStep) {
  Session s(pour(2000));
  for (int i = 0; i < 20; ++i) s.single_step();  // rows are re-sorted by the grid from here on
  auto before = positions_by_entity(s.world());
  // Half a step of real time twice: one step is taken, and the loop is half way to the next.
  s.advance(0.75 * kStep);
  ASSERT_EQ(s.advance(0.75 * kStep), 1);
  SphereRenderState r = s.sphere_render_state();
  EXPECT_NEAR(r.alpha, 0.5f, 1e-3f);
  ASSERT_FALSE(r.previous_by_entity.empty());
  std::size_t moved = 0;
  for (std::size_t i = 0; i < r.position.size(); ++i) {
    const Vec3& previous = r.previous_by_entity[r.entity[i]];
    EXPECT_EQ(previous, before.at(r.entity[i])) << "row " << i;  // bit for bit: a copy, not a guess
    if (previous != r.position[i]) ++moved;
  }
  EXPECT_GT(moved, r.position.size() / 2);  // the pour is falling: there is something to blend
}

TEST(Session, PausedSingleStepsAndResetsDrawTheLatestStateAsItIs) {
  Session s(pour(500));
  s.advance(kStep * 1.5);
  EXPECT_LT(s.alpha(), 1.0f);
  s.paused = true;
  EXPECT_EQ(s.advance(1.0), 0);
  EXPECT_EQ(s.alpha(), 1.0f);
  s.paused = false;
  s.single_step();
  EXPECT_EQ(s.alpha(), 1.0f);
  EXPECT_TRUE(s.sphere_render_state().previous_by_entity.empty());
}

TEST(Session, PouringAddsBallsAboveThePile) {
  Session s(pour(1000));
  for (int i = 0; i < 5; ++i) s.single_step();
  float top = 0.0f;
  for (const Vec3& p : s.world().spheres.position()) top = std::max(top, p.y());
  const std::uint64_t version = s.sphere_render_state().version;
  s.pour(700);
  ASSERT_EQ(s.world().spheres.size(), 1700u);
  EXPECT_NE(s.sphere_render_state().version, version);  // the renderer must re-upload
  std::size_t above = 0;
  for (const Vec3& p : s.world().spheres.position()) above += p.y() > top;
  EXPECT_EQ(above, 700u);
  s.single_step();  // and the new balls simulate
  EXPECT_EQ(s.world().spheres.size(), 1700u);
}

TEST(Session, ResetRebuildsTheSceneButKeepsTheSolverSettingsTheUserChose) {
  Session s(pour(800));
  s.set_substeps(3);
  s.set_solve_sweeps(2);
  s.set_restitution(0.8f);
  for (int i = 0; i < 10; ++i) s.single_step();
  s.pour(100);
  s.reset();
  EXPECT_EQ(s.world().spheres.size(), 800u);
  EXPECT_EQ(s.world().solver.substeps, 3);
  EXPECT_EQ(s.world().solver.solve_sweeps, 2);
  EXPECT_FLOAT_EQ(s.world().materials.front().restitution, 0.8f);
  EXPECT_FLOAT_EQ(s.world().pit.material.restitution, 0.8f);
  // The same balls in the same places as a fresh session's.
  Session fresh(pour(800));
  fresh.set_substeps(3);
  fresh.set_solve_sweeps(2);
  fresh.set_restitution(0.8f);
  EXPECT_EQ(state_hash(s.world()), state_hash(fresh.world()));
}

// A scene file in the app: its populations, its character (the collider switch survives a
// reset), --spheres as the first population's count, and errors that name the file.
TEST(Session, ASceneFileBuildsItsPopulationsAndCharacter) {
  SessionOptions o;
  o.scene = BALLPIT_SCENES_DIR "/mixed.json";
  o.set = {"populations.1.count=40", "populations.2.count=30"};
  o.spheres = 200;
  o.threads = 2;
  Session mixed(o);
  EXPECT_EQ(mixed.world().spheres.size(), 270u);
  EXPECT_FALSE(mixed.has_character());
  mixed.single_step();
  mixed.reset();
  EXPECT_EQ(mixed.world().spheres.size(), 270u);

  o.scene = BALLPIT_SCENES_DIR "/pit_character.json";
  o.set = {"character.control=player"};
  o.spheres = 300;
  Session walker(o);
  ASSERT_TRUE(walker.has_character());
  const std::size_t balls = walker.world().spheres.size();
  EXPECT_EQ(balls, 300u);
  walker.set_character_input(ControllerInput{.forward = 1.0f});
  for (int i = 0; i < 30; ++i) walker.single_step();
  EXPECT_GT(walker.character_position().norm(), 0.05f);  // the keyboard drives it
  walker.set_collider_kind(ColliderKind::Spheres);
  walker.reset();
  EXPECT_EQ(walker.world().characters.setup(0).collider_kind, ColliderKind::Spheres);
  EXPECT_EQ(walker.world().spheres.size(), balls);

  o.set = {"character.colour=3"};
  try {
    Session bad(o);
    ADD_FAILURE() << "an unknown field was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pit_character.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("character.colour"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Session(SessionOptions{.scene = "pour", .set = {"steps=3"}}), Error);  // --set needs a file
}

TEST(Session, OutOfRangeSettingsAreRefusedWithTheirName) {
  Session s(pour(100));
  EXPECT_THROW(s.set_restitution(1.5f), Error);
  EXPECT_THROW(s.set_friction(-0.1f), Error);
  EXPECT_THROW(s.set_substeps(0), Error);
  EXPECT_THROW(s.set_solve_sweeps(0), Error);
  EXPECT_THROW(s.set_solve_sweeps(kMaxSolveSweeps + 1), Error);
  EXPECT_EQ(s.world().solver.solve_sweeps, 1);  // refused, so unchanged
  EXPECT_THROW(Session(SessionOptions{.scene = "swamp"}), Error);
}

TEST(Controls, KeysMapToControllerInput) {
  EXPECT_EQ(controller_input({.forward = true}).forward, 1.0f);
  EXPECT_EQ(controller_input({.back = true}).forward, -1.0f);
  EXPECT_EQ(controller_input({.forward = true, .back = true}).forward, 0.0f);
  EXPECT_EQ(controller_input({.left = true}).turn, 1.0f);  // +1 turns left
  EXPECT_EQ(controller_input({.right = true}).turn, -1.0f);
  EXPECT_TRUE(controller_input({.forward = true, .run = true}).run);
  EXPECT_TRUE(controller_input({.jump = true}).jump);
  EXPECT_TRUE(controller_input({.kick = true}).kick);
  EXPECT_FALSE(controller_input({.jump = true}).kick);
}

class PlaySession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { session_ = new Session(play(3000)); }
  static void TearDownTestSuite() {
    delete session_;
    session_ = nullptr;
  }
  static Session* session_;
};
Session* PlaySession::session_ = nullptr;

TEST_F(PlaySession, TwoSecondsOfTheForwardKeyWalkTheCharacterForwardOnScreen) {
  Session& s = *session_;
  s.reset();
  ASSERT_TRUE(s.has_character());
  OrbitCamera camera;
  camera.frame_pit(s.world().pit.half_width, s.fill_height());
  const Viewport view{1280, 720};
  const CharacterMotion& m = s.world().characters.motion(0);
  const Vec3 start = m.current.position;
  const float heading = m.current.heading;
  const Vec2 start_px = camera.project(start, view).pixel;

  for (int frame = 0; frame < 120; ++frame) {  // 2 s of 60 Hz frames with W held
    s.set_character_input(controller_input({.forward = true}));
    s.single_step();
  }
  const Vec3 moved = m.current.position - start;
  // The model faces +z at heading 0; heading turns it left (counter-clockwise from above).
  const Vec3 forward(std::sin(heading), 0.0f, std::cos(heading));
  const float walk = s.world().characters.setup(0).controller.walk_speed;
  // 2 s at walk speed, less the ramp up at the controller's acceleration (a few cm).
  EXPECT_GT(moved.dot(forward), 0.8f * walk * 2.0f);
  EXPECT_LT(moved.dot(forward), 1.01f * walk * 2.0f);
  EXPECT_LT((moved - moved.dot(forward) * forward).norm(), 0.01f);  // straight, no drift
  const Vec2 end_px = camera.project(m.current.position, view).pixel;
  // The camera frames a ~7.7 m pit on 720 rows: 0.8 m is tens of pixels.
  EXPECT_GT((end_px - start_px).norm(), 10.0f);
}

TEST_F(PlaySession, SpaceJumpsAndKKicksTheMarine) {
  Session& s = *session_;
  for (const auto& [keys, action] : {std::pair{KeyState{.jump = true}, kJump}, std::pair{KeyState{.kick = true}, kKick}}) {
    s.reset();
    s.set_character_input(controller_input(keys));
    s.single_step();
    EXPECT_EQ(s.world().characters.pose(0).action, action);
    s.set_character_input(controller_input({}));  // let go: the action plays out, then stops
    for (int frame = 0; frame < 120; ++frame) s.single_step();
    EXPECT_EQ(s.world().characters.pose(0).action, -1);
  }
}

TEST_F(PlaySession, ShiftMakesTheSameKeysRun) {
  // The ground speed reached after 1 s of each: walking at 1.4 m/s by then; running still
  // speeding up at the controller's 3 m/s^2 towards 3.5 m/s, so at about 3 m/s.
  Session& s = *session_;
  auto speed = [&](bool run) {
    s.reset();
    for (int frame = 0; frame < 60; ++frame) {
      s.set_character_input(controller_input({.forward = true, .run = run}));
      s.single_step();
    }
    return s.world().characters.motion(0).current.speed;
  };
  const float walking = speed(false);
  const float running = speed(true);
  EXPECT_NEAR(walking, s.world().characters.setup(0).controller.walk_speed, 0.01f);
  EXPECT_GT(running, 1.8f * walking);
}

TEST_F(PlaySession, SwitchingColliderKindKeepsTheCharacterWhereItStands) {
  Session& s = *session_;
  s.reset();
  for (int frame = 0; frame < 30; ++frame) {
    s.set_character_input(controller_input({.forward = true, .left = true}));
    s.single_step();
  }
  const RootState before = s.world().characters.motion(0).current;
  s.set_collider_kind(ColliderKind::Spheres);
  const ColliderTable& c = s.world().colliders;
  ASSERT_GT(c.size(), 0u);
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_EQ(c.a()[i], c.b()[i]) << "collider " << i << " is not a sphere";
  const RootState after = s.world().characters.motion(0).current;
  // Same spot and heading; the height follows the new colliders' reach below the root.
  EXPECT_EQ(after.position.x(), before.position.x());
  EXPECT_EQ(after.position.z(), before.position.z());
  EXPECT_EQ(after.heading, before.heading);
  EXPECT_GT(after.position.y() + s.world().characters.setup(0).lowest_collider, 0.0f);  // clear of the floor
  s.single_step();  // and the new colliders simulate
  s.set_collider_kind(ColliderKind::Capsules);
  std::size_t capsules = 0;
  for (std::size_t i = 0; i < c.size(); ++i) capsules += c.a()[i] != c.b()[i];
  EXPECT_GT(capsules, 0u);
}
