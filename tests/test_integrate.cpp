#include <gtest/gtest.h>

#include "systems/integrate.h"
#include "tiny_world.h"

using namespace ballpit;

TEST(Integrate, FreeFallFollowsTheExactParabola) {
  World w;
  test::make_pit(w, 10.0f, 0.0f, 0.0f);
  Entity e = test::add_ball(w, Vec3(0, 100, 0), Vec3(1, 0, 0));
  const float h = 1.0f / 240.0f;
  const int n = 240;
  for (int i = 0; i < n; ++i) {
    integrate_velocities(w.spheres, w.gravity(), h, w.solver);
    integrate_positions(w.spheres, h, w.gravity());
  }
  const Vec3 v = w.spheres.velocity()[w.spheres.row(e)];
  const Vec3 x = w.spheres.position()[w.spheres.row(e)];
  // Constant gravity: v = g t and x = x0 - g t^2 / 2 exactly. Tolerance: float rounding over
  // 240 additions, a few ulps of 10 m/s and 100 m.
  const float t = n * h;
  EXPECT_NEAR(v.y(), -9.81f * t, 1e-4f);
  EXPECT_NEAR(x.y(), 100.0f - 0.5f * 9.81f * t * t, 1e-3f);
  EXPECT_NEAR(x.x(), 1.0f, 1e-4f);
}

TEST(Integrate, SleepingSpheresDoNotMove) {
  World w;
  test::make_pit(w, 10.0f, 0.0f, 0.0f);
  Entity e = test::add_ball(w, Vec3(0, 1, 0));
  w.spheres.mut_asleep()[w.spheres.row(e)] = 1;
  integrate_velocities(w.spheres, w.gravity(), 0.01f, w.solver);
  integrate_positions(w.spheres, 0.01f, w.gravity());
  EXPECT_EQ(w.spheres.position()[w.spheres.row(e)], Vec3(0, 1, 0));
  EXPECT_EQ(w.spheres.velocity()[w.spheres.row(e)], Vec3::Zero());
}

TEST(Integrate, APushedSphereMovesBySymplecticEulerSoRestingContactStaysAtRest) {
  // A contact cancelled the gravity kick: v = 0 must mean no motion, not the parabola's sag.
  World w;
  test::make_pit(w, 10.0f, 0.0f, 0.0f);
  Entity e = test::add_ball(w, Vec3(0, 1, 0));
  std::vector<std::uint8_t> pushed{1};
  integrate_positions(w.spheres, 0.01f, w.gravity(), pushed);
  EXPECT_EQ(w.spheres.position()[w.spheres.row(e)], Vec3(0, 1, 0));
}

TEST(Integrate, DampingIsImplicitAndNeverReversesVelocity) {
  World w;
  test::make_pit(w, 10.0f, 0.0f, 0.0f);
  w.set_gravity(Vec3::Zero());
  w.solver.linear_damping = 1000.0f;  // absurd: explicit 1 - c h would flip the sign
  Entity e = test::add_ball(w, Vec3(0, 1, 0), Vec3(1, 0, 0));
  integrate_velocities(w.spheres, w.gravity(), 0.01f, w.solver);
  float vx = w.spheres.velocity()[w.spheres.row(e)].x();
  EXPECT_GT(vx, 0.0f);
  EXPECT_NEAR(vx, 1.0f / (1.0f + 10.0f), 1e-6f);
}
