#include <gtest/gtest.h>

#include <algorithm>

#include "engine/metrics.h"
#include "engine/pour_scene.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {

void sleepy_pit(World& w) {
  test::make_pit(w, 1.0f, 0.0f, 0.5f);
  w.solver.sleeping = true;
}

bool asleep(const test::Sim& s, Entity e) { return s.world.spheres.asleep()[s.world.spheres.row(e)] != 0; }

}  // namespace

TEST(Sleeping, AStillBallFallsAsleepAfterSleepTime) {
  test::Sim s;
  sleepy_pit(s.world);
  Entity e = test::add_ball(s.world, Vec3(0, 0.04f, 0));
  s.start();
  const int steps_to_sleep = static_cast<int>(s.world.solver.sleep_time / s.world.step()) + 2;
  s.step(steps_to_sleep);
  EXPECT_TRUE(asleep(s, e));
  EXPECT_EQ(s.velocity(e), Vec3::Zero());
}

TEST(Sleeping, ASleeperCostsNoContacts) {
  test::Sim s;
  sleepy_pit(s.world);
  Entity a = test::add_ball(s.world, Vec3(0, 0.04f, 0));
  Entity b = test::add_ball(s.world, Vec3(0.0801f, 0.04f, 0));
  s.start();
  s.step(60);
  ASSERT_TRUE(asleep(s, a));
  ASSERT_TRUE(asleep(s, b));
  EXPECT_EQ(s.world.contacts.pair_count(), 0u);  // sleeper pairs are not even listed
  EXPECT_EQ(s.world.contacts.static_count(), 2u);  // their floors are (cheap), for waking
}

TEST(Sleeping, ASleeperWakesBeforeItIsStruckAndTakesTheBlow) {
  // A ball rolling at a sleeper at 1 m/s: the sleeper must be awake before contact, so it is
  // knocked away (e = 0: the pair shares the momentum) rather than stopping the ball dead as
  // a fixed body would.
  test::Sim s;
  sleepy_pit(s.world);
  Entity a = test::add_ball(s.world, Vec3(0, 0.04f, 0));
  s.start();
  s.step(60);
  ASSERT_TRUE(asleep(s, a));
  Entity c = test::add_ball(s.world, Vec3(-0.5f, 0.04f, 0), Vec3(1, 0, 0));
  s.step(60);  // it rolls (5/7 of 1 m/s once friction has spun it up): contact near step 35
  EXPECT_FALSE(asleep(s, a));
  EXPECT_GT(s.velocity(a).x(), 0.2f) << "a took the blow";
  EXPECT_LT(s.velocity(c).x(), 0.8f) << "c gave some of its momentum away";
}

TEST(Sleeping, ChangingGravityWakesEveryone) {
  test::Sim s;
  sleepy_pit(s.world);
  Entity e = test::add_ball(s.world, Vec3(0, 0.04f, 0));
  s.start();
  s.step(60);
  ASSERT_TRUE(asleep(s, e));
  s.world.set_gravity(Vec3(9.81f, 0, 0));
  EXPECT_FALSE(asleep(s, e));
  s.step(10);
  EXPECT_GT(s.velocity(e).x(), 0.5f);
}

namespace {

// The canonical pour at 1,000 balls with sleeping on (SCENES.md measures it with sleeping off).
void sleepy_pour(test::Sim& s) {
  PourScene scene;
  scene.spheres = 1000;
  scene.build(s.world);
  s.world.solver.sleeping = true;
  s.start(2);
}

std::size_t sleepers(const World& w) {
  auto a = w.spheres.asleep();
  return static_cast<std::size_t>(std::count(a.begin(), a.end(), std::uint8_t{1}));
}

}  // namespace

TEST(Sleeping, ASettledPileFallsAsleepWholeAndStaysAtRest) {
  // Balls that slept one by one inside the pile were fixed bodies that no longer passed on
  // their weight; waking, they woke their neighbours, and the pour never came to rest (10k
  // balls, 1,200 steps: 0.25 J and overlaps of 0.12 r left). The pile must end as it does with
  // sleeping off: all of it asleep, and no overlap beyond 1% r.
  test::Sim s;
  sleepy_pour(s);
  s.step(900);  // 15 s: the pile is at rest long before (sleeping off: 3e-6 J after 20 s at 10k)
  ASSERT_EQ(sleepers(s.world), s.world.spheres.size());
  const std::size_t pair_entries = s.world.contacts.warm.size();
  s.step(120);
  EXPECT_EQ(sleepers(s.world), s.world.spheres.size()) << "something woke the sleeping pile";
  // A sleeping pile keeps its loads (the warm-start entries of its pairs), to wake warm.
  EXPECT_EQ(s.world.contacts.warm.size(), pair_entries);
  const Metrics m = measure(s.world);
  EXPECT_LT(m.max_penetration_r, 0.01);
  EXPECT_EQ(m.kinetic_energy_j, 0.0);
}

TEST(Sleeping, ASleepingPileStruckByABallWakesAndComesToRestAgain) {
  // One ball dropped on the sleeping pile wakes the pile it lands on, all of it; woken warm, the
  // pile takes the blow and settles again instead of boiling.
  test::Sim s;
  sleepy_pour(s);
  s.step(900);
  ASSERT_EQ(sleepers(s.world), s.world.spheres.size());
  float top = 0.0f;
  for (const Vec3& x : s.world.spheres.position()) top = std::max(top, x.y());
  test::add_ball(s.world, Vec3(0.0f, top + 0.5f, 0.0f));
  s.step(30);  // falls 0.5 m in about 0.32 s, and lands
  EXPECT_LT(sleepers(s.world), s.world.spheres.size() / 2) << "the pile it landed on woke";
  float fastest = 0.0f;
  for (int k = 0; k < 600; ++k) {
    s.step();
    for (const Vec3& v : s.world.spheres.velocity()) fastest = std::max(fastest, v.norm());
  }
  // The ball lands at sqrt(2 g 0.5) = 3.1 m/s; nothing in the pile may go faster than that.
  EXPECT_LT(fastest, 3.2f);
  EXPECT_EQ(sleepers(s.world), s.world.spheres.size()) << "the pile came to rest and slept again";
  EXPECT_LT(measure(s.world).max_penetration_r, 0.01);
}

TEST(Sleeping, APileWokenByAMoverKeepsItsSupportInTheStepItWakes) {
  // The wake system runs after the narrowphase, which lists no pair of two sleepers: a pile it
  // woke had no contacts among its balls for that step and fell freely for it (all of them at
  // g dt = 0.16 m/s, and overlaps of 0.09 r three steps later). A woken pile must be solved
  // with its contacts in the step it wakes. Here its top ball is thrown upward; the balls it
  // leaves have no reason to move.
  test::Sim s;
  sleepy_pour(s);
  s.step(900);
  ASSERT_EQ(sleepers(s.world), s.world.spheres.size());
  auto x = s.world.spheres.position();
  const std::uint32_t top = static_cast<std::uint32_t>(
      std::max_element(x.begin(), x.end(), [](const Vec3& a, const Vec3& b) { return a.y() < b.y(); }) - x.begin());
  const Entity thrown = s.world.spheres.entity_at(top);
  // Woken by hand, as the narrowphase finds it: awake and moving (a sleeper has no velocity).
  s.world.spheres.mut_asleep()[top] = 0;
  s.world.spheres.mut_still_time()[top] = 0.0f;
  s.world.spheres.mut_velocity()[top] = Vec3(0.0f, 1.0f, 0.0f);
  s.step();
  // A ball or two may rest apart from the pile, on the floor alone (6 of these 1,000).
  EXPECT_LT(sleepers(s.world), s.world.spheres.size() / 100) << "the pile it left woke";
  float fastest_left = 0.0f;
  auto v = s.world.spheres.velocity();
  for (std::uint32_t i = 0; i < v.size(); ++i)
    if (s.world.spheres.entity_at(i) != thrown) fastest_left = std::max(fastest_left, v[i].norm());
  // Free fall for the step would be 0.16 m/s; the pile at rest, as it was, moves by solver noise.
  EXPECT_LT(fastest_left, 0.02f);
  s.step(3);
  EXPECT_LT(measure(s.world).max_penetration_r, 0.01);
}
