// The contact solver on worlds of one to three spheres, against closed-form answers.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <map>
#include <utility>

#include "engine/error.h"
#include "engine/metrics.h"
#include "engine/pour_scene.h"
#include "engine/snapshot.h"
#include "engine/state_hash.h"
#include "engine/thread_share.h"
#include "systems/batch_kernels.h"
#include "systems/grid.h"
#include "systems/narrowphase.h"
#include "systems/solver.h"
#include "tiny_world.h"

using namespace ballpit;

TEST(Solver, ABallRestingOnTheFloorStaysAtRest) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.5f, 0.5f);
  Entity e = test::add_ball(s.world, Vec3(0, 0.04f, 0));
  s.start();
  s.step(600);
  // Rigid contact, overlap pushed out each substep: the ball sits at r to float precision; the
  // bound leaves room for the speculative stop of each substep's fall (g h^2, 4 um).
  EXPECT_NEAR(s.position(e).y(), 0.04f, 0.001f * 0.04f);
  EXPECT_LT(s.velocity(e).norm(), 1e-4f);
}

TEST(Solver, OverlappingSpheresSeparateNoFasterThanThePushOutCap) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.0f, 0.0f);
  s.world.set_gravity(Vec3::Zero());
  s.world.solver.push_out_speed = 0.5f;
  Entity a = test::add_ball(s.world, Vec3(-0.01f, 0.5f, 0));
  Entity b = test::add_ball(s.world, Vec3(0.01f, 0.5f, 0));  // 75% overlap
  s.start();
  float max_speed = 0;
  for (int i = 0; i < 120; ++i) {
    s.step();
    max_speed = std::max({max_speed, s.velocity(a).norm(), s.velocity(b).norm()});
  }
  EXPECT_GT((s.position(b) - s.position(a)).norm(), 0.08f * 0.99f);  // apart (within 1% of 2r)
  // Relaxation removes the push-out velocity after each substep: what is left stays far
  // below the cap.
  EXPECT_LE(max_speed, 0.5f);
}

TEST(Solver, PushOutNeverCarriesABallDeepIntoThePit) {
  // A ball 0.3 r from the floor or a wall, at rest, has no contact with it yet (its margin is
  // 0.05 r); a ball twenty times heavier spawned 1.8 r into it from the other side pushes it
  // there at nearly the push-out cap, 1.6 r in a step. Without the pit guard it ends the step
  // with its centre past the plane.
  const float r = 0.04f, half = 1.0f;
  for (const Vec3& out : {Vec3(0, -1, 0), Vec3(1, 0, 0)}) {  // the floor, the +x wall
    test::Sim s;
    test::make_pit(s.world, half, 0.0f, 0.0f);
    s.world.set_gravity(Vec3::Zero());
    const Vec3 plane_point = out.y() < 0 ? Vec3(0, 0, 0) : Vec3(half, 0.5f, 0);
    Entity near = test::add_ball(s.world, plane_point - 1.3f * r * out);
    Entity heavy = test::add_ball(s.world, plane_point - 1.5f * r * out, Vec3::Zero(), r, 1.0f);
    s.start();
    s.step();
    const float depth_r = ((s.position(near) - plane_point).dot(out) + r) / r;
    EXPECT_GT(depth_r, 0.9f) << out.transpose();  // the push did reach the plane: the case above
    EXPECT_LE(depth_r, 1.0f + 1e-5f) << out.transpose();  // the guard's bound, to float precision
    s.step(60);
    // And the plane's contact takes the rest: the ball rests on it, the heavy one on the ball.
    EXPECT_NEAR((s.position(near) - plane_point).dot(out), -r, 0.01f * r) << out.transpose();
    EXPECT_NEAR((s.position(near) - s.position(heavy)).dot(out), 2 * r, 0.01f * r) << out.transpose();
  }
}

TEST(Solver, ChangingTheSubstepsLeavesARestingPileAtRest) {
  // The warm-start cache holds impulses of one substep. A pile resting at 3 substeps, switched
  // to 32, warm-starts each of them with ten times its load unless World::set_substeps scales
  // the cache. What a switch does is measured against the same pile stepped on without it
  // (restored from a snapshot), over the two steps after it: a pile that looks at rest may still
  // slip on its own (a ball wedged sideways under another left at 0.13 m/s, 65 steps after the
  // pile passed 0.001 m/s, with or without a switch), and two substep counts then tell the slip
  // apart more every step. Over 21 piles (the upper layers' nudge from 0.02 to 0.4 r) the scaled
  // switch changed a ball's velocity by at most 0.0105 m/s from 3 to 32 substeps (a finer split
  // redistributes impulses that were not the converged ones) and 0.0006 from 32 to 2; unscaled,
  // over 8 of them, by at least 0.063 and 0.16. The bound lies between.
  test::Sim s;
  test::make_pit(s.world, 0.3f, 0.5f, 0.5f);
  s.world.solver.substeps = 3;
  const float r = 0.04f;
  std::vector<Entity> balls;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      for (int k = 0; k < 6; ++k)  // columns, every other layer nudged so they settle
        balls.push_back(
            test::add_ball(s.world, Vec3(-0.24f + 2 * r * i + 0.1f * r * (k % 2), r + 2.0025f * r * k, -0.24f + 2 * r * j)));
  s.start();
  s.step(180);
  ASSERT_LT(measure(s.world).max_speed_mps, 0.001) << "the pile must rest before the switch";
  for (int substeps : {32, 2}) {
    Snapshot before;
    capture_snapshot(s.world, before);
    test::Sim kept;
    restore_snapshot(before, kept.world);
    kept.start();
    s.world.set_substeps(substeps);
    double made = 0.0;  // the largest change of any ball's velocity that the switch made
    for (int i = 0; i < 2; ++i) {
      s.step();
      kept.step();
      for (const Entity e : balls) made = std::max(made, static_cast<double>((s.velocity(e) - kept.velocity(e)).norm()));
    }
    EXPECT_LT(made, 0.02) << "after switching to " << substeps << " substeps";
    s.step(60);
  }
  EXPECT_THROW(s.world.set_substeps(0), Error);
}

TEST(Solver, ASlidingBallEndsRollingAtFiveSeventhsOfItsSpeed) {
  // A solid sphere launched sliding on a rough floor: friction turns sliding into rolling,
  // and angular momentum about the contact point conserves v_final = 5/7 v0.
  test::Sim s;
  test::make_pit(s.world, 10.0f, 0.0f, 0.5f);
  Entity e = test::add_ball(s.world, Vec3(-5, 0.04f, 0), Vec3(2, 0, 0));
  s.start();
  s.step(120);
  const Vec3 v = s.velocity(e);
  const Vec3 w = s.world.spheres.angular_velocity()[s.world.spheres.row(e)];
  EXPECT_NEAR(v.x(), 2.0f * 5.0f / 7.0f, 0.01f * 2.0f * 5.0f / 7.0f);  // 1%: substep friction steps
  EXPECT_NEAR(w.z(), -v.x() / 0.04f, 0.01f * v.x() / 0.04f);           // rolls without slipping
}

TEST(Solver, ABallSpinningOnTheFloorStopsAtItsSpinningFrictionsRate) {
  // Spinning friction (systems/contact_kernel.h): a torque of mu N kTwistArmFraction r about the
  // floor's normal slows w by mu g kTwistArmFraction kSphereSpinFactor / r = 30.66 rad/s^2 here
  // (N is the ball's weight from the first substep on). Spun at 10 rad/s about the vertical, it
  // turns at 10 - 30.66 / 6 = 4.89 rad/s after 10 steps, then stops for good: friction never
  // reverses a spin. The 0.1% slack is float rounding over 40 substeps.
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.0f, 0.5f);
  const float r = 0.04f;
  Entity e = test::add_ball(s.world, Vec3(0, r, 0));
  s.world.spheres.mut_angular_velocity()[s.world.spheres.row(e)] = Vec3(0, 10, 0);
  s.start();
  auto spin = [&] { return s.world.spheres.angular_velocity()[s.world.spheres.row(e)]; };
  s.step(10);
  const float slowing = 0.5f * 9.81f * kTwistArmFraction * kSphereSpinFactor / r;
  EXPECT_NEAR(spin().y(), 10.0f - slowing / 6.0f, 0.001f * 10.0f);
  s.step(20);
  EXPECT_EQ(spin().y(), 0.0f);
  EXPECT_LT(s.velocity(e).norm(), 1e-6f) << "a twist moves nothing";
}

TEST(Solver, WithoutRestitutionABallDoesNotBounce) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.0f, 0.0f);
  Entity e = test::add_ball(s.world, Vec3(0, 0.5f, 0));
  s.start();
  float highest_after_landing = 0;
  bool landed = false;
  for (int i = 0; i < 120; ++i) {
    s.step();
    if (s.position(e).y() < 0.045f) landed = true;
    if (landed) highest_after_landing = std::max(highest_after_landing, s.position(e).y());
  }
  EXPECT_TRUE(landed);
  EXPECT_LT(highest_after_landing, 0.04f * 1.01f);
}

TEST(Solver, AJointColliderPushesABallAtItsSurfaceSpeed) {
  // An infinitely heavy collider moving at 1 m/s into a ball at rest (no gravity, e = 1): the
  // ball leaves at 2 m/s, the reflection in the collider's frame (the report's formula).
  test::Sim s;
  test::make_pit(s.world, 10.0f, 1.0f, 0.0f);
  s.world.set_gravity(Vec3::Zero());
  s.world.solver.restitution_threshold = 0.0f;
  Entity ball = test::add_ball(s.world, Vec3(0, 1, 0));
  ColliderDesc d;
  d.shape = ColliderShape::Sphere;
  d.a = Vec3(-0.3f, 1, 0);
  d.radius = 0.1f;
  d.velocity_a = Vec3(1, 0, 0);
  std::uint32_t c = s.world.colliders.add(d);
  s.start();
  for (int i = 0; i < 30; ++i) {
    s.step();
    Vec3 p = s.world.colliders.a()[c] + Vec3(1, 0, 0) * s.world.step();
    s.world.colliders.set_pose(c, p, p, d.velocity_a, d.velocity_a);
  }
  EXPECT_NEAR(s.velocity(ball).x(), 2.0f, 0.02f);
  EXPECT_NEAR(s.velocity(ball).y(), 0.0f, 1e-4f);
}

TEST(Solver, ALoadedPileDoesNotBoilAtFewSubsteps) {
  // A pile at few substeps: impacts inside it, and the exact-bounce correction of a sphere
  // resting on others, once pumped energy in (2,000 balls at 2 substeps: 3.3 J and balls at
  // 4 m/s after 10 s). Loaded contacts are never struck and piled spheres are not shifted,
  // so the pile comes to rest.
  test::Sim s;
  PourScene scene;
  scene.spheres = 2000;
  scene.build(s.world);
  s.world.solver.substeps = 2;
  s.start();
  s.step(600);
  const Metrics m = measure(s.world);
  // At rest: far below one ball dropped through its own radius (m g r = 0.02 J) in all; the
  // settled pile holds under a millijoule.
  EXPECT_LT(m.kinetic_energy_j, 0.01);
  EXPECT_LT(m.max_speed_mps, 0.25);  // nothing moves at the restitution threshold
  EXPECT_EQ(m.escaped, 0u);
}

TEST(Solver, KeptPairFramesGiveTheStateOfFramesRecomputedInEveryPass) {
  // The solver keeps a pair's frame from Relax for the next substep, and computes them all
  // again after an impact shift has moved a sphere. Balls poured onto the floor and onto each
  // other strike and shift in most steps of the pour; one stale frame changes the hash (checked
  // by making the solver ignore shifts: the hashes then differ).
  auto pour_hash = [](bool keep) {
    test::Sim s;
    PourScene scene;
    scene.spheres = 1000;
    scene.build(s.world);
    s.world.solver.keep_pair_frames = keep;
    s.start();
    s.step(240);
    return hash_hex(state_hash(s.world));
  };
  EXPECT_EQ(pour_hash(true), pour_hash(false));
}

namespace {

// The pour's first 2 s at 1,500 balls (falling, striking the floor and each other, piling up),
// stepped by hand so each test chooses the solver's scratch; its state hash at the end.
std::string pour_hash_with(SolverScratch& scratch) {
  World w;
  PourScene scene;
  scene.spheres = 1500;
  scene.build(w);
  GridSystem grid;
  NarrowphaseScratch narrow;
  for (int i = 0; i < 120; ++i) {
    grid.run(w);
    find_contacts(w, narrow);
    solve_contacts(w, scratch);
  }
  return hash_hex(state_hash(w));
}

}  // namespace

TEST(Solver, EveryInstructionSetGivesTheSameState) {
  // The lane kernels are one source compiled for AVX-512, AVX2 and any CPU, with IEEE-exact
  // operations only: each must give every bit the others give. (This CPU may lack the wide
  // ones; the plain kernels always run.)
  const std::vector<const BatchKernels*> kernels = available_batch_kernels();
  SolverScratch reference;
  reference.kernels = kernels.front();
  const std::string expected = pour_hash_with(reference);
  for (const BatchKernels* k : kernels) {
    SolverScratch scratch;
    scratch.kernels = k;
    EXPECT_EQ(pour_hash_with(scratch), expected) << k->name;
  }
}

TEST(Solver, HowSlabsAreGroupedChangesNoBit) {
  // Slabs of one parity share no sphere, so packing them one to a group or several changes the
  // lanes they fill, not the result.
  SolverScratch alone, together, by_contacts;
  alone.slabs_per_group = 1;
  together.slabs_per_group = 5;
  const std::string expected = pour_hash_with(alone);
  EXPECT_EQ(pour_hash_with(together), expected);
  EXPECT_EQ(pour_hash_with(by_contacts), expected);  // the default: cut by contacts
}

TEST(Solver, IntegratingInTheSweepsChangesNoBit) {
  // Each thread kicks and moves its own rows in its even sweep instead of on an equal share of
  // rows; on any team and any grouping that must be the same arithmetic on every body, in time
  // for every contact that touches it.
  const FullTeams full;  // the solver on the whole team: 1,500 spheres alone would get one thread
  for (int threads : {1, 2})
    for (int slabs : {0, 1}) {
      const TeamSize team(threads);
      SolverScratch own, in_sweeps;
      own.integrate_in_sweeps = false;
      own.slabs_per_group = in_sweeps.slabs_per_group = slabs;
      const std::string expected = pour_hash_with(own);
      EXPECT_TRUE(own.even_group_rows.empty());
      EXPECT_EQ(pour_hash_with(in_sweeps), expected) << threads << " threads, slabs per group " << slabs;
      EXPECT_FALSE(in_sweeps.even_group_rows.empty());  // the sweeps did integrate
    }
}

// One Gauss-Seidel sweep a substep hands a push only a few balls into a pile; more sweeps hand it
// further, so fewer substeps hold the pile. The 2,000-ball pour at 2 substeps ends 12.6% of r deep
// with 1 sweep, 0.94% with 2 and 0.19% with 3 (measured); the bounds leave room for the chaos
// of which pair ends deepest. Sweeps change nothing of the parallel scheme: 2 threads give 1's bits.
TEST(Solver, MoreSolveSweepsHoldAPileAtFewerSubsteps) {
  auto pour = [](int sweeps, int threads) {
    test::Sim s;
    PourScene scene;
    scene.spheres = 2000;
    scene.build(s.world);
    s.world.set_substeps(2);
    s.world.set_solve_sweeps(sweeps);
    s.start(threads);
    s.step(600);
    return std::pair(measure(s.world), state_hash(s.world));
  };
  const auto [one, one_hash] = pour(1, 1);
  const auto [three, three_hash] = pour(3, 1);
  EXPECT_GT(one.max_penetration_r, 0.05);
  EXPECT_LT(three.max_penetration_r, 0.01);
  EXPECT_EQ(three.escaped, 0u);
  EXPECT_NE(one_hash, three_hash);
  EXPECT_EQ(pour(3, 2).second, three_hash);
}

TEST(Solver, AnyTeamGivesTheStateOfOneThread) {
  // Threads wait for each other only where their groups meet (systems/solver.cpp, Step::sweep):
  // a group swept before a group it meets is through, or while it is still being swept, would
  // show here. More threads than cores (this machine has 2) and one slab to a group give the
  // most meeting groups on different threads, in the most interleavings.
  const FullTeams full;  // the solver on the whole team: 1,500 spheres alone would get one thread
  for (int slabs : {0, 1}) {
    SolverScratch one;
    one.slabs_per_group = slabs;
    std::string expected;
    {
      const TeamSize team(1);
      expected = pour_hash_with(one);
    }
    for (int threads : {2, 3, 4}) {
      const TeamSize team(threads);
      ASSERT_EQ(omp_get_max_threads(), threads) << "the solver must run on the team asked for";
      SolverScratch scratch;
      scratch.slabs_per_group = slabs;
      EXPECT_EQ(pour_hash_with(scratch), expected) << threads << " threads, slabs per group " << slabs;
    }
  }
}

TEST(Solver, DefaultGroupsGiveEachThreadAnEqualShare) {
  // A thread takes whole groups, so groups of unequal work, or a number of groups the team does
  // not divide, leave one thread waiting on the other at the end of every pass. 12k spheres: a
  // pit 26 slabs wide, 13 of each parity, which no number of equal-sized groups splits evenly.
  const TeamSize two(2);
  World w;
  PourScene scene;
  scene.spheres = 12000;
  scene.build(w);
  GridSystem grid;
  NarrowphaseScratch narrow;
  SolverScratch scratch;
  for (int i = 0; i < 60; ++i) {
    grid.run(w);
    find_contacts(w, narrow);
    solve_contacts(w, scratch);
  }
  // The groups of the last step, against the contacts it found.
  const std::vector<SlabContacts>& slabs = w.contacts.slabs;
  for (int parity = 0; parity < 2; ++parity) {
    std::size_t total = 0, largest_slab = 0;
    for (std::size_t s = static_cast<std::size_t>(parity); s < slabs.size(); s += 2) {
      const std::size_t contacts = slabs[s].pairs.size() + slabs[s].statics.size();
      total += contacts;
      largest_slab = std::max(largest_slab, contacts);
    }
    const std::vector<std::size_t>& before = scratch.contacts_before[parity];
    const int groups = static_cast<int>(scratch.groups[parity].size());
    ASSERT_EQ(before.size(), scratch.groups[parity].size() + 1);
    ASSERT_EQ(before.back(), total);
    EXPECT_EQ(groups % 2, 0) << "parity " << parity;
    for (int t = 0; t < 2; ++t) {
      const auto [first, last] = share_of(t, 2, groups, [&](int g) { return before[static_cast<std::size_t>(g)]; });
      const std::size_t share = before[static_cast<std::size_t>(last)] - before[static_cast<std::size_t>(first)];
      EXPECT_LE(share, total / 2 + largest_slab) << "parity " << parity << ", thread " << t;
    }
  }
}

// The solver reads the pile marks the narrowphase makes with the contacts (ContactSet::piled);
// called on a world whose contacts were never found, it says so instead of reading past them.
TEST(Solver, RefusesAWorldWhoseContactsTheNarrowphaseDidNotFind) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.5f, 0.5f);
  test::add_ball(s.world, Vec3(0, 0.04f, 0));
  test::add_ball(s.world, Vec3(0, 0.12f, 0));
  try {
    solve_contacts(s.world);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("narrowphase must run first"), std::string::npos) << e.what();
  }
}

// What the next step starts from: the solver caches each contact's impulse under its generating
// row and partner. In a resting stack of three each contact carries the weight above it, one
// substep's worth: m g h under the top ball, 2 m g h under the middle, 3 m g h on the floor.
TEST(Solver, TheWarmStartCacheHoldsTheLoadOfEachContactOfAStack) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.0f, 0.5f);
  const float r = 0.04f, m = 0.05f;
  Entity balls[3];
  for (int k = 0; k < 3; ++k) balls[k] = test::add_ball(s.world, Vec3(0, r + 2.0f * r * static_cast<float>(k), 0), Vec3::Zero(), r, m);
  s.start(2);
  s.step(120);
  const float weight = m * s.world.gravity().norm() * s.world.step() / static_cast<float>(s.world.solver.substeps);

  const ContactSet& cache = s.world.contacts;
  auto entity = s.world.spheres.entity_index();
  std::map<std::pair<std::uint32_t, std::uint32_t>, float> load;  // entity pair (floor: kPlaneTag) -> impulse
  for (std::size_t row = 0; row < entity.size(); ++row)
    for (std::uint32_t k = cache.warm_begin[row]; k < cache.warm_begin[row + 1]; ++k) {
      const WarmStartEntry& e = cache.warm[k];
      EXPECT_FALSE(load.contains({std::min(entity[row], e.partner), std::max(entity[row], e.partner)})) << "cached twice";
      load[{std::min(entity[row], e.partner), std::max(entity[row], e.partner)}] = e.normal_impulse;
    }
  ASSERT_EQ(load.size(), 3u);
  const std::uint32_t bottom = balls[0].index, middle = balls[1].index, top = balls[2].index;
  EXPECT_NEAR(load.at({bottom, kPlaneTag | 0u}), 3.0f * weight, 0.01f * weight);
  EXPECT_NEAR(load.at({std::min(bottom, middle), std::max(bottom, middle)}), 2.0f * weight, 0.01f * weight);
  EXPECT_NEAR(load.at({std::min(middle, top), std::max(middle, top)}), weight, 0.01f * weight);
}
