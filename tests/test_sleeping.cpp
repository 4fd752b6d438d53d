#include <gtest/gtest.h>

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
