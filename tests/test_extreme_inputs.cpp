// Extreme inputs (issue 40, points 1 and 2): heavy gravity, long steps, tiny and huge balls, balls
// fired at 100 m/s. Each must keep what a sphere lists near its neighbours (the cost guard) and
// let no ball pass through another, the floor or a wall. Passes of a step (engine/step_passes.h)
// and the margin cap (engine/speculative_margin.h) are what these tests hold to account.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/pour_scene.h"
#include "engine/speculative_margin.h"
#include "engine/state_hash.h"
#include "engine/step_passes.h"
#include "engine/thread_share.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {

// A split step's passes keep every margin within kSplitMarginFraction r, so a sphere lists
// partners whose centres lie within (2 + 2 x 1) r = 4 r of its own: at most 0.74 x 4^3 = 47 of
// equal radius (0.74: the densest packing of spheres). A step run whole keeps margins within the
// cap, 2.5 r: at most 0.74 x 7^3 = 254.
constexpr int kMostPartnersSplit = 47;
constexpr int kMostPartnersWhole = 254;

// Partners listed per sphere by the last pass of the last step: the most any sphere has, and
// the mean.
struct Listed {
  int most = 0;
  double mean = 0.0;
};

Listed listed_partners(const World& w) {
  std::vector<int> partners(w.spheres.size(), 0);
  std::size_t pairs = 0;
  for (const SlabContacts& slab : w.contacts.slabs)
    for (const auto* list : {&slab.pairs, &slab.serial})
      for (const Contact& c : *list) {
        ++partners[c.a];
        ++partners[c.b];
        ++pairs;
      }
  Listed l;
  l.most = partners.empty() ? 0 : *std::max_element(partners.begin(), partners.end());
  l.mean = partners.empty() ? 0.0 : 2.0 * static_cast<double>(pairs) / static_cast<double>(partners.size());
  return l;
}

// What the cost guard saw over a test (printed for the record, as "listed partners").
struct ListedOverRun {
  int most = 0;
  double mean_sum = 0.0, mean_max = 0.0;
  int steps = 0, most_passes = 0;
  void print(const char* where) {
    std::printf("[ listed   ] %s: partners a sphere, most %d, mean %.2f (worst step %.2f); most passes %d\n", where, most,
                steps ? mean_sum / steps : 0.0, mean_max, most_passes);
    *this = {};
  }
};
ListedOverRun listed_over_run;

// The cost guard, after a step: within the bound that its passes' margins give.
void expect_near_neighbours_only(const World& w, const char* where) {
  const Listed l = listed_partners(w);
  listed_over_run.most = std::max(listed_over_run.most, l.most);
  listed_over_run.mean_sum += l.mean;
  listed_over_run.mean_max = std::max(listed_over_run.mean_max, l.mean);
  listed_over_run.most_passes = std::max(listed_over_run.most_passes, w.passes.passes);
  ++listed_over_run.steps;
  const int bound = w.passes.passes > 1 ? kMostPartnersSplit : kMostPartnersWhole;
  EXPECT_LE(l.most, bound) << where << ", step " << w.step_count << " (" << w.passes.passes << " passes)";
}

// The deepest sphere-sphere overlap, as a fraction of the smaller radius (all pairs: tiny worlds).
double deepest_overlap_r(const World& w) {
  auto x = w.spheres.position();
  auto r = w.spheres.radius();
  double deepest = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      const double depth = r[i] + r[j] - (x[i] - x[j]).norm();
      deepest = std::max(deepest, depth / std::min(r[i], r[j]));
    }
  return deepest;
}

// Spheres whose centre is outside the pit's walls or below its floor (beyond 1% r of slack for
// the solver's last push).
int escaped(const World& w) {
  int out = 0;
  auto x = w.spheres.position();
  auto r = w.spheres.radius();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const float slack = 0.01f * r[i];
    const bool outside = x[i].y() < -slack || std::abs(x[i].x()) > w.pit.half_width + slack ||
                         std::abs(x[i].z()) > w.pit.half_width + slack;
    out += outside;
  }
  return out;
}

// A cubic lattice of n^3 balls of radius r, `spacing` radii apart, its lowest layer at y0, centred
// on x = z = 0 (or at x0), with a jitter of +-1% r from a fixed hash so nothing is symmetric.
std::vector<Entity> lattice(World& w, int nx, int ny, int nz, float r, float spacing, float y0, const Vec3& v = Vec3::Zero(),
                            float mass = 0.05f, float x0 = 0.0f) {
  std::vector<Entity> balls;
  const float step = spacing * r;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int k = 0; k < nz; ++k) {
        const unsigned h = static_cast<unsigned>(i * 73856093 ^ j * 19349663 ^ k * 83492791);
        const float jitter = 0.01f * r * (static_cast<float>(h % 201) / 100.0f - 1.0f);
        const Vec3 p(x0 + (static_cast<float>(i) - 0.5f * (nx - 1)) * step + jitter, y0 + static_cast<float>(j) * step,
                     (static_cast<float>(k) - 0.5f * (nz - 1)) * step - jitter);
        balls.push_back(test::add_ball(w, p, v, r, mass));
      }
  return balls;
}

// How close the straight path of b relative to a over one step (from d0 to d1) comes to a's
// centre. A ball that passes through another crosses within one radius of its centre; one that
// bounces or rolls off keeps at least about the contact distance.
double closest_approach(const Vec3& d0, const Vec3& d1) {
  const Vec3 e = d1 - d0;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp(-static_cast<double>(d0.dot(e)) / len2, 0.0, 1.0) : 0.0;
  return (d0 + static_cast<float>(t) * e).norm();
}

// Steps the world, checking after every step that no tracked ball's path crossed within one
// radius of another ball's centre (it passed through it), and the cost guard.
void step_tracking(test::Sim& s, const std::vector<Entity>& tracked, int steps, const char* where) {
  for (int n = 0; n < steps; ++n) {
    std::vector<Vec3> before(s.world.spheres.position().begin(), s.world.spheres.position().end());
    std::vector<Entity> entity_of_row(before.size());
    for (std::size_t row = 0; row < before.size(); ++row) entity_of_row[row] = s.world.spheres.entity_at(static_cast<std::uint32_t>(row));
    s.step();
    expect_near_neighbours_only(s.world, where);
    auto x = s.world.spheres.position();
    auto r = s.world.spheres.radius();
    // Rows are re-sorted every step: a ball's old position is found by its old row.
    std::vector<std::size_t> row_now(before.size());
    for (std::size_t old = 0; old < before.size(); ++old) row_now[old] = s.world.spheres.row(entity_of_row[old]);
    for (std::size_t old_i = 0; old_i < before.size(); ++old_i) {
      const Entity e = entity_of_row[old_i];
      if (std::find(tracked.begin(), tracked.end(), e) == tracked.end()) continue;
      const std::size_t i = row_now[old_i];
      for (std::size_t old_j = 0; old_j < before.size(); ++old_j) {
        if (old_j == old_i) continue;
        const Entity other = entity_of_row[old_j];
        const std::size_t j = row_now[old_j];
        const double d = closest_approach(before[old_i] - before[old_j], x[i] - x[j]);
        if (d < 0.5 * (r[i] + r[j])) {
          ADD_FAILURE() << where << ": ball " << to_string(e) << " passed within " << d / r[i] << " r of the centre of "
                        << to_string(other) << " in step " << s.world.step_count;
          return;
        }
      }
    }
  }
}

}  // namespace

TEST(ExtremeInputs, TheCanonicalPourRunsEveryStepAsOnePass) {
  // The pour's fastest ball (about 4.7 m/s after a 1.1 m fall) has a margin of 1.97 r, within
  // the cap: every step is one pass at dt, so the pour's results are those from before passes.
  test::Sim s;
  PourScene scene;
  scene.spheres = 1000;
  scene.build(s.world);
  s.start();
  for (int n = 0; n < 120; ++n) {
    s.step();
    ASSERT_EQ(s.world.passes.passes, 1) << "step " << n;
    expect_near_neighbours_only(s.world, "pour");
  }
  listed_over_run.print("pour, 1,000 balls, 120 steps");
}

TEST(ExtremeInputs, AHeavyGravityPileSettlesWithoutDeepPairsOrEscapes) {
  // 300 balls of the pour (not 1,000: the suites also run under TSan and ASan, and 1,000 took 3 s
  // in Release) at gravity 1e4 m/s^2 for 1 s. A top ball falls 1.2 m and lands at about 155 m/s.
  // The solver needs more than the pour's settings to hold a pile that weighs a thousand times
  // more: at its push-out cap of 4 m/s and 4 substeps the 1,000-ball pile sank into itself (1.99 r,
  // mean 0.66 r) whatever the passes; at 100 m/s and 16 substeps it kept 0.114 r. Holding a pile
  // within a tolerance is the error control's work (issue 40, point 3); these settings are given.
  test::Sim s;
  PourScene scene;
  scene.spheres = 300;
  scene.build(s.world);
  s.world.set_gravity(Vec3(0.0f, -1.0e4f, 0.0f));
  s.world.solver.push_out_speed = 100.0f;
  s.world.set_substeps(16);
  s.start();
  int most_passes = 0;
  for (int n = 0; n < 60; ++n) {
    s.step();
    most_passes = std::max(most_passes, s.world.passes.passes);
    expect_near_neighbours_only(s.world, "heavy");
    ASSERT_EQ(s.world.passes.steps_short, 0u) << "step " << n;
  }
  listed_over_run.print("heavy, 300 balls, 1 s");
  EXPECT_GT(most_passes, 1);  // the heavy pile is split into passes
  // 0.114 r measured at 1,000 balls; 0.25 r leaves room and is far from passing through (2 r).
  EXPECT_LT(deepest_overlap_r(s.world), 0.25);
  EXPECT_EQ(escaped(s.world), 0);
}

TEST(ExtremeInputs, BallsFiredAtAHundredMetresASecondIntoARestingPileDoNotPassThrough) {
  // 400 resting balls (a 10 x 4 x 10 stack, touching) and 100 fired straight down at 100 m/s from
  // 1 m above it: 1.67 m (42 r) a step, 43 passes of 0.39 ms. (The SCENES volley fires 500 into
  // 10,000; this is its tiny world.)
  test::Sim s;
  test::make_pit(s.world, 0.45f, 0.5f, 0.5f);
  const float r = 0.04f;
  lattice(s.world, 10, 4, 10, r, 2.0f, r);
  const std::vector<Entity> fired = lattice(s.world, 5, 4, 5, r, 2.2f, 1.3f, Vec3(0.0f, -100.0f, 0.0f));
  s.start();
  step_tracking(s, fired, 30, "volley down");
  listed_over_run.print("volley down, 100 into 400");
  for (Entity e : fired) EXPECT_GT(s.position(e).y(), r * 0.99f) << "under the floor: " << to_string(e);
  EXPECT_EQ(escaped(s.world), 0);
  EXPECT_EQ(s.world.passes.steps_short, 0u);
  // Pairs the impacts pressed together, still being pushed apart: far from passing (2 r).
  EXPECT_LT(deepest_overlap_r(s.world), 0.5);
}

TEST(ExtremeInputs, BallsFiredAtAHundredMetresASecondAtAWallStayInsideIt) {
  // 100 balls fired along +x at 100 m/s from 0.3 m inside the wall, over a row of 50 resting
  // balls against it: none may pass the wall or the balls before it. The pit has a lid 2 m up:
  // open, it let one ball that the impacts threw up at tens of m/s fly over its 20 m walls.
  test::Sim s;
  test::make_pit(s.world, 0.5f, 0.5f, 0.5f, /*closed=*/true, /*height=*/2.0f);
  const float r = 0.04f;
  lattice(s.world, 1, 2, 10, r, 2.0f, r, Vec3::Zero(), 0.05f, 0.5f - r);
  const std::vector<Entity> fired = lattice(s.world, 4, 5, 5, r, 2.2f, r, Vec3(100.0f, 0.0f, 0.0f), 0.05f, -0.1f);
  s.start();
  step_tracking(s, fired, 30, "volley at a wall");
  listed_over_run.print("volley at a wall, 100 at 20");
  for (Entity e : fired) EXPECT_LT(s.position(e).x(), 0.5f - 0.99f * r) << "through the wall: " << to_string(e);
  EXPECT_EQ(escaped(s.world), 0);
}

TEST(ExtremeInputs, AStepOfATenthOfASecondKeepsThePileApart) {
  // 200 pour balls at dt = 0.1 s, 2 s. The substeps are those the long-substep warning asks for
  // (accurate_substeps: 24); at the pour's 4 a substep of 25 ms softens every contact and the
  // 1,000-ball pile sank 0.94 r, which is the error control's matter, not a pass-through.
  test::Sim s;
  PourScene scene;
  scene.spheres = 200;
  scene.build(s.world);
  s.world.set_step(0.1f);
  s.world.set_substeps(accurate_substeps(0.1f));
  s.start();
  for (int n = 0; n < 20; ++n) {
    s.step();
    expect_near_neighbours_only(s.world, "dt 0.1 s");
  }
  listed_over_run.print("dt 0.1 s, 200 balls");
  EXPECT_EQ(s.world.passes.steps_short, 0u);
  EXPECT_LT(deepest_overlap_r(s.world), 0.25);
  EXPECT_EQ(escaped(s.world), 0);
}

// Radii at the ends of the allowed range, the same pile scaled: 125 balls dropped from 2 radii to
// 22 radii above the floor. A ball of 1e-4 m moves 40 r in a step at 0.25 m/s.
void drop_pile(float r, int* most_passes) {
  test::Sim s;
  test::make_pit(s.world, 6.0f * r, 0.5f, 0.5f);
  const float mass = 0.05f * std::pow(r / 0.04f, 3.0f);  // the pour's density
  const std::vector<Entity> balls = lattice(s.world, 5, 5, 5, r, 2.2f, 2.0f * r, Vec3::Zero(), mass);
  s.start();
  *most_passes = 0;
  for (int n = 0; n < 60; ++n) {
    s.step();
    *most_passes = std::max(*most_passes, s.world.passes.passes);
    expect_near_neighbours_only(s.world, "drop");
  }
  listed_over_run.print(r < 0.01f ? "drop, r = 1e-4 m" : "drop, r = 1 m");
  EXPECT_EQ(s.world.passes.steps_short, 0u);
  // A 5-high pile of these balls overlaps under 1% r at r = 0.04 m; a smaller ball weighs as
  // much, in radii, as a pile of 0.04 m balls under 400 g, so it sinks deeper, yet far from 2 r.
  EXPECT_LT(deepest_overlap_r(s.world), 0.25) << "r = " << r;
  EXPECT_EQ(escaped(s.world), 0) << "r = " << r;
}

TEST(ExtremeInputs, ATenthOfAMillimetreBallDoesNotPassThrough) {
  int most_passes = 0;
  drop_pile(1e-4f, &most_passes);
  EXPECT_GT(most_passes, 1);  // 0.6 mm of fall at 1/60 s is many radii a step
}

TEST(ExtremeInputs, AOneMetreBallPileRunsAsBefore) {
  int most_passes = 0;
  drop_pile(1.0f, &most_passes);
  EXPECT_EQ(most_passes, 1);  // a few m/s is a small fraction of a metre per step
}

TEST(ExtremeInputs, MotionThatNeedsMorePassesThanAStepMayTakeIsWarnedOf) {
  // Balls of 1e-4 m under 1e4 m/s^2 at dt = 0.1 s: a resting ball alone needs passes of 0.2 ms,
  // 500 of them, past kMostPassesPerStep.
  test::Sim s;
  test::make_pit(s.world, 1e-3f, 0.5f, 0.5f);
  lattice(s.world, 3, 2, 3, 1e-4f, 2.2f, 1e-4f, Vec3::Zero(), 1e-6f);
  s.world.set_gravity(Vec3(0.0f, -1.0e4f, 0.0f));
  s.world.set_step(0.1f);
  EXPECT_NE(s.world.step_warnings().passes.find("dt of"), std::string::npos) << s.world.step_warnings().passes;
  s.start();
  std::vector<std::string> warnings;
  s.loop->warn = [&](const std::string& w) { warnings.push_back(w); };
  s.step(3);
  EXPECT_EQ(s.world.passes.passes, kMostPassesPerStep);
  EXPECT_GT(s.world.passes.needed, kMostPassesPerStep);
  EXPECT_EQ(s.world.passes.steps_short, 3u);
  ASSERT_EQ(warnings.size(), 1u);  // at once, and once
  EXPECT_NE(warnings[0].find("passes"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("dt of"), std::string::npos) << warnings[0];
  EXPECT_EQ(s.world.step(), 0.1f);  // the passes leave dt as it was
}

TEST(ExtremeInputs, PassesGiveTheSameStateForAnyThreadCount_UnderTwoOpenMPThreads) {
  auto run = [](int threads) {
    omp_set_num_threads(threads);
    const FullTeams full;
    test::Sim s;
    test::make_pit(s.world, 0.45f, 0.5f, 0.5f);
    lattice(s.world, 10, 3, 10, 0.04f, 2.0f, 0.04f);
    lattice(s.world, 4, 3, 4, 0.04f, 2.2f, 1.0f, Vec3(0.0f, -100.0f, 0.0f));
    s.start(threads);
    s.step(10);
    return state_hash(s.world);
  };
  EXPECT_EQ(hash_hex(run(1)), hash_hex(run(2)));
}

TEST(ExtremeInputs, TheProfilerCountsAStepOfSeveralPassesAsOneFrame) {
  // The per-system table's medians are per step (engine/profiler.h): counted per pass, a run
  // whose steps split showed the cost of a pass, a fraction of its steps'.
  test::Sim s;
  test::make_pit(s.world, 0.45f, 0.5f, 0.5f);
  lattice(s.world, 4, 1, 4, 0.04f, 2.2f, 0.04f);
  lattice(s.world, 2, 1, 2, 0.04f, 2.2f, 0.6f, Vec3(0.0f, -30.0f, 0.0f));
  s.start();
  const int steps = 10;
  int passes = 0;
  for (int k = 0; k < steps; ++k) {
    s.step();
    passes += s.world.passes.passes;
  }
  ASSERT_GT(passes, steps) << "the balls fired at 30 m/s should split some steps";
  const std::vector<SystemStats> stats = s.scheduler->profiler().stats();
  ASSERT_FALSE(stats.empty());
  for (const SystemStats& system : stats) EXPECT_EQ(system.frames, static_cast<std::size_t>(steps)) << system.name;
}

TEST(StepPasses, PlanFromTheFastestBallAndGravity) {
  // v h + g h^2 / 4 = (cap - minimum) r, for the fastest ball and for gravity alone.
  World w;
  test::add_ball(w, Vec3(0, 1, 0), Vec3(0, -100, 0), 0.04f);
  w.set_gravity(Vec3::Zero());
  EXPECT_NEAR(longest_capped_pass(w, 1.0f), 0.98f * 0.04f / 100.0f, 1e-9);
  w.set_gravity(Vec3(0, -1e4f, 0));
  World rest;
  test::add_ball(rest, Vec3(0, 1, 0), Vec3::Zero(), 0.04f);
  rest.set_gravity(Vec3(0, -1e4f, 0));
  EXPECT_NEAR(longest_capped_pass(rest, 1.0f), std::sqrt(0.98f * 0.04f / 2500.0f), 1e-7);
  EXPECT_LT(longest_capped_pass(w, 1.0f), longest_capped_pass(rest, 1.0f));
  EXPECT_EQ(passes_needed(1.0f / 60.0f, 1.0f), 1);
  EXPECT_EQ(passes_needed(1.0f, 0.1f), 10);
  EXPECT_EQ(passes_needed(1.0f, 0.0f), std::numeric_limits<std::int32_t>::max());
  EXPECT_FLOAT_EQ(capped_pair_margin(1e6f, 1.0f, 0.0f, 0.04f), kMostMarginFraction * 0.04f);
  EXPECT_EQ(capped_pair_margin(0.0f, 1.0f / 60.0f, 9.81f, 0.04f), pair_margin(0.0f, 1.0f / 60.0f, 9.81f, 0.04f));
}

TEST(ExtremeInputs, GravityThatOutrunsThePushOutIsWarnedOf) {
  // The heavy scene at the pour's solver settings sinks into itself (engine/world.h,
  // kMostGravityPerSubstepOfPushOut); the settings its test runs at, and the pour's own, hold.
  World w;
  PourScene scene;
  scene.spheres = 100;
  scene.build(w);
  EXPECT_EQ(w.step_warnings().gravity, "");
  w.set_gravity(Vec3(0.0f, -1.0e4f, 0.0f));
  const std::string warning = w.step_warnings().gravity;
  EXPECT_NE(warning.find("push-out cap"), std::string::npos) << warning;
  EXPECT_NE(warning.find("holds it"), std::string::npos) << warning;
  w.solver.push_out_speed = 100.0f;
  w.set_substeps(16);
  EXPECT_EQ(w.step_warnings().gravity, "");
}
