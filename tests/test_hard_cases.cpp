// The numerically hard cases of issue 2. Each asserts numbers against an exact or reference
// answer; every tolerance says where it comes from.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "engine/metrics.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {
constexpr float kR = 0.04f;  // the pour scene's ball radius (unit: m)
}

TEST(HardCases, AStackOfFiftyRestsTwentySecondsWithoutMovingOrSinking) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.5f, 0.5f);
  std::vector<Entity> stack;
  for (int i = 0; i < 50; ++i) stack.push_back(test::add_ball(s.world, Vec3(0, kR + 2 * kR * i, 0)));
  s.start();
  // Placed touching, the column first takes its load: one Gauss-Seidel sweep per substep
  // hands the floor's support up 50 balls slowly, and push-out recovers the sag after. At the
  // default 4 substeps the top sags 1.9 r by 5 s and is back within 0.5% r of full height by
  // 35 s (measured); then it must rest 20 s.
  s.step(45 * 60);
  std::vector<Vec3> start;
  for (Entity e : stack) start.push_back(s.position(e));
  double worst_overlap = 0;
  for (int i = 0; i < 20 * 60; ++i) {
    s.step();
    if (i % 10 == 0) {
      Metrics m = measure(s.world);
      worst_overlap = std::max({worst_overlap, m.max_penetration_r, m.max_wall_penetration_r});
    }
  }
  double worst_move = 0;
  for (std::size_t i = 0; i < stack.size(); ++i)
    worst_move = std::max(worst_move, static_cast<double>((s.position(stack[i]) - start[i]).norm()));
  EXPECT_LT(worst_move, 0.01 * kR);
  EXPECT_LT(worst_overlap, 0.01);
  // And it stands near its full height: rigid contacts, no spring sag. 49 contacts at the
  // 1% r overlap bound could lose 49% r; measured 0.16% r in all (moved 0.00005 r at rest).
  EXPECT_NEAR(s.position(stack.back()).y(), kR + 2 * kR * 49, 0.025 * kR);
}

TEST(HardCases, ADroppedBallBouncesToESquaredOfItsHeight) {
  // Exact: each bounce rises to e^2 of the height it fell from. The apex of each rise is read
  // from the first state after the bounce as y + vy^2 / 2g (free flight is a parabola; sampling
  // the top at 60 Hz would itself be up to g dt^2 / 8 low, 2% of a 1.6 cm bounce). Free flight
  // is integrated exactly and impacts are resolved at their time within the substep, so what
  // is left is O(g h^2) in the contact substep: 0.65% at the default 4 substeps (0.5% at 6,
  // 0.3% at 8), three bounces deep (profiling/reports/speed_error.md, bounce). 1% is the
  // issue's bound.
  const float g = 9.81f;
  for (float e : {0.5f, 0.8f}) {
    test::Sim s;
    test::make_pit(s.world, 1.0f, e, 0.0f);
    const float drop = 1.0f;  // height of the ball's bottom above the floor (unit: m)
    Entity ball = test::add_ball(s.world, Vec3(0, kR + drop, 0));
    s.start();
    std::vector<float> heights{drop};
    float last_vy = 0;
    for (int i = 0; i < 900 && heights.size() < 4; ++i) {
      s.step();
      float y = s.position(ball).y() - kR, vy = s.velocity(ball).y();
      if (vy > 0 && last_vy <= 0) heights.push_back(y + vy * vy / (2 * g));
      last_vy = vy;
    }
    ASSERT_EQ(heights.size(), 4u) << "three bounces, e = " << e;
    for (std::size_t k = 1; k < heights.size(); ++k)
      EXPECT_NEAR(heights[k] / heights[k - 1], e * e, 0.01f * e * e) << "e = " << e << ", bounce " << k;
  }
}

TEST(HardCases, EqualSpheresHeadOnWithEOneSwapVelocities) {
  test::Sim s;
  test::make_pit(s.world, 2.0f, 1.0f, 0.0f);
  s.world.set_gravity(Vec3::Zero());
  s.world.solver.restitution_threshold = 0.0f;
  Entity a = test::add_ball(s.world, Vec3(-0.5f, 1, 0), Vec3(1, 0, 0));
  Entity b = test::add_ball(s.world, Vec3(0.5f, 1, 0), Vec3(-0.5f, 0, 0));
  s.start();
  s.step(60);
  // Float rounding in one impulse: 1e-5 m/s.
  EXPECT_NEAR(s.velocity(a).x(), -0.5f, 1e-5f);
  EXPECT_NEAR(s.velocity(b).x(), 1.0f, 1e-5f);
  // They met where exact kinematics says: apart by 2r + 1.5 m/s * time since contact.
  const float t_contact = (1.0f - 2 * kR) / 1.5f, t = 1.0f;
  EXPECT_NEAR(s.position(b).x() - s.position(a).x(), 2 * kR + 1.5f * (t - t_contact), 1e-3f);
}

TEST(HardCases, NewtonsCradlePassesTheMomentumToTheLastBall) {
  // Five touching balls, the first struck at 1 m/s from either side: the far one leaves at
  // 1 m/s (within 1%) and momentum is conserved to float precision. The others are left with
  // up to 2% of the striker's speed: each impact is resolved within its substep, but the
  // pairs touch exactly, and the push-out of the overlaps left by the impact shifts returns a
  // little motion. 3% bounds that.
  for (float dir : {1.0f, -1.0f}) {
    test::Sim s;
    test::make_pit(s.world, 2.0f, 1.0f, 0.0f);
    s.world.set_gravity(Vec3::Zero());
    s.world.solver.restitution_threshold = 0.0f;
    std::vector<Entity> row;
    for (int i = 0; i < 5; ++i) row.push_back(test::add_ball(s.world, Vec3(dir * 2 * kR * i, 1, 0)));
    Entity striker = test::add_ball(s.world, Vec3(-dir * 0.3f, 1, 0), Vec3(dir, 0, 0));
    s.start();
    s.step(30);
    EXPECT_NEAR(s.velocity(row.back()).x(), dir, 0.01f) << "direction " << dir;
    EXPECT_NEAR(s.velocity(striker).x(), 0.0f, 0.03f);
    float momentum = s.velocity(striker).x();
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(s.velocity(row[i]).x(), 0.0f, 0.03f) << "ball " << i;
      momentum += s.velocity(row[i]).x();
    }
    momentum += s.velocity(row.back()).x();
    EXPECT_NEAR(momentum, dir, 1e-5f);
  }
}

// A crowd: the push-out cap it separates at and the seed of its random spawn. The default cap
// (4 m/s since the speed-against-error study showed a 1 m/s cap lets the overlap linger and
// feed real speed) over several spawns, since one spawn can be lucky: before the solver stopped
// reading overlaps deeper than one move as impacts (systems/contact_kernel.h, beyond_reach),
// seeds 9, 15 and 16 broke the bound that seed 7 met at the default cap, and seed 15 at 1 m/s.
// Of seeds 1 to 30, 28 still broke it at the default cap (by 8.3 m/s) and 6, 10, 18 and 30 at
// 1 m/s (by up to 2.7) until a pile pressing a ball into the floor stopped counting as an
// impact; since then the worst of the 60 runs is 0.23 m/s under the bound.
struct Crowd {
  float push_out_speed;  // (unit: m/s)
  unsigned seed;
};

class CrowdAtCap : public ::testing::TestWithParam<Crowd> {};

TEST_P(CrowdAtCap, ACrowdSpawnedInATenthOfItsVolumeSeparatesCalmly) {
  test::Sim s;
  const int n = 1000;
  // The crowd needs n (2r)^3 of space; it gets a tenth, as a cube at the pit's centre.
  const float side = std::cbrt(0.1f * n * std::pow(2 * kR, 3.0f));
  test::make_pit(s.world, 0.6f, 0.5f, 0.5f);
  s.world.solver.push_out_speed = GetParam().push_out_speed;
  std::mt19937 rng(GetParam().seed);
  std::uniform_real_distribution<float> u(-0.5f * side, 0.5f * side);
  for (int i = 0; i < n; ++i) test::add_ball(s.world, Vec3(u(rng), 0.3f + u(rng), u(rng)));
  s.start(2);
  // Bound: the push-out cap plus what gravity adds since the start (restitution can only
  // return part of the speed a contact took away), and the cap counts for at most 1 m/s: a
  // larger cap removes overlap faster, which must not make any ball faster.
  const double cap = std::min(s.world.solver.push_out_speed, 1.0f);
  double fastest_excess = -1e9;
  for (int i = 0; i < 300; ++i) {
    s.step();
    Metrics m = measure(s.world);
    double bound = cap + 9.81 * s.world.step() * (i + 1);
    fastest_excess = std::max(fastest_excess, m.max_speed_mps - bound);
    ASSERT_EQ(m.escaped, 0u) << "step " << i;
  }
  EXPECT_LE(fastest_excess, 0.0);
  Metrics end = measure(s.world);
  EXPECT_LT(end.max_penetration_r, 0.05);  // separated: the pile is resting at 5 s
}

constexpr float kDefaultCap = SolverSettings{}.push_out_speed;
INSTANTIATE_TEST_SUITE_P(HardCases, CrowdAtCap,
                         ::testing::Values(Crowd{1.0f, 6}, Crowd{1.0f, 7}, Crowd{1.0f, 10}, Crowd{1.0f, 15},
                                           Crowd{1.0f, 18}, Crowd{1.0f, 30}, Crowd{kDefaultCap, 7}, Crowd{kDefaultCap, 9},
                                           Crowd{kDefaultCap, 15}, Crowd{kDefaultCap, 16}, Crowd{kDefaultCap, 28}),
                         [](const ::testing::TestParamInfo<Crowd>& point) {
                           const Crowd& c = point.param;
                           return (c.push_out_speed == kDefaultCap ? std::string("DefaultCap") : std::string("OneMetrePerSecond")) +
                                  "Seed" + std::to_string(c.seed);
                         });

TEST(HardCases, AHundredMetresPerSecondBallNeitherTunnelsThroughABallNorTheWall) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.5f, 0.0f);
  Entity resting = test::add_ball(s.world, Vec3(0.5f, kR, 0));
  Entity bullet = test::add_ball(s.world, Vec3(-0.9f, kR, 0), Vec3(100, 0, 0));
  s.start();
  for (int i = 0; i < 120; ++i) {
    s.step();
    for (Entity e : {resting, bullet}) {
      ASSERT_LE(std::abs(s.position(e).x()), 1.0f - kR + 0.01f * kR) << "through a wall at step " << i;
    }
    ASSERT_LT(s.position(bullet).x(), s.position(resting).x()) << "through the ball at step " << i;
    ASSERT_LT(measure(s.world).max_penetration_r, 0.01) << "step " << i;
  }
}

TEST(HardCases, AnElasticGasKeepsItsEnergyForTenThousandSteps) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 1.0f, 0.0f, /*closed=*/true, /*height=*/2.0f);
  s.world.set_gravity(Vec3::Zero());
  s.world.solver.restitution_threshold = 0.0f;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f), y(0.1f, 1.9f), v(-1.0f, 1.0f);
  // 2000 balls at 1.7% of the box volume, placed without overlap.
  std::vector<Vec3> placed;
  while (placed.size() < 2000) {
    Vec3 p(u(rng), y(rng), u(rng));
    bool free = true;
    for (const Vec3& q : placed) free = free && (p - q).squaredNorm() > 4.4f * kR * kR;
    if (free) placed.push_back(p);
  }
  for (const Vec3& p : placed) test::add_ball(s.world, p, Vec3(v(rng), v(rng), v(rng)));
  s.start(2);
  const double e0 = measure(s.world).kinetic_energy_j;
  s.step(10000);
  const double e1 = measure(s.world).kinetic_energy_j;
  EXPECT_NEAR(e1, e0, 0.01 * e0);
}

TEST(HardCases, SphereCollisionsConserveMomentumToFloatPrecision) {
  // A dense cloud in the middle of a big box, zero gravity: for the first 60 steps no ball
  // reaches a wall, so only sphere-sphere impulses act, and each is applied equal and
  // opposite. Tolerance: float rounding of each velocity update, 1e-6 of the momentum scale.
  test::Sim s;
  test::make_pit(s.world, 5.0f, 0.5f, 0.5f, /*closed=*/true, /*height=*/10.0f);
  s.world.set_gravity(Vec3::Zero());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.4f, 0.4f), v(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) test::add_ball(s.world, Vec3(u(rng), 5.0f + u(rng), u(rng)), Vec3(v(rng), v(rng), v(rng)));
  s.start(2);
  Metrics m0 = measure(s.world);
  double scale = 0;
  for (float iv : s.world.spheres.inv_mass()) scale += 1.0 / iv * std::sqrt(3.0);
  for (int i = 0; i < 60; ++i) {
    s.step();
    ASSERT_EQ(s.world.contacts.static_count(), 0u) << "a ball reached a wall: the test lost its premise";
  }
  Metrics m1 = measure(s.world);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(m1.momentum[a], m0.momentum[a], 1e-6 * scale) << "axis " << a;
  EXPECT_GT(m1.overlapping_pairs + s.world.contacts.pair_count(), 100u) << "the cloud must collide to test anything";
}

TEST(HardCases, GravityTurnedFullCircleSpillsNoBallFromAClosedBox) {
  test::Sim s;
  const std::size_t n = 10000;
  const float half = 0.5f * std::sqrt(n * 5.6e-4f);  // the pour pit's width, closed at 2 half-widths
  test::make_pit(s.world, half, 0.5f, 0.5f, /*closed=*/true, /*height=*/2 * half);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.002f, 0.002f);
  const float spacing = 2.2f * kR;
  const int per_row = static_cast<int>((2 * half - 2 * kR) / spacing);
  for (std::size_t i = 0; i < n; ++i) {
    int ix = static_cast<int>(i % per_row), iz = static_cast<int>((i / per_row) % per_row),
        iy = static_cast<int>(i / (per_row * per_row));
    test::add_ball(s.world, Vec3(-half + kR + spacing * (ix + 0.5f) + jitter(rng), kR + 0.01f + spacing * iy,
                                 -half + kR + spacing * (iz + 0.5f) + jitter(rng)));
  }
  s.start(2);
  const int steps = 600;  // 10 s at 60 Hz
  for (int i = 0; i < steps; ++i) {
    float angle = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / steps;
    s.world.set_gravity(9.81f * Vec3(std::sin(angle), -std::cos(angle), 0));
    s.step();
    if (i % 30 == 29) {
      Metrics m = measure(s.world);
      ASSERT_EQ(m.escaped, 0u) << "step " << i;
      ASSERT_LT(m.max_wall_penetration_r, 0.5) << "step " << i;
    }
  }
}
