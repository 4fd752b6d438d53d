// The narrowphase finds every pair that may touch this step, once, and the grid finds exactly
// the pairs the all-pairs reference finds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "engine/thread_share.h"
#include "systems/grid.h"
#include "systems/narrowphase.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {

using PairSet = std::set<std::pair<std::uint32_t, std::uint32_t>>;  // entity indices, ordered

PairSet sphere_pairs(const World& w) {
  PairSet out;
  auto entity = w.spheres.entity_index();
  for (const SlabContacts& s : w.contacts.slabs)
    for (const auto* list : {&s.pairs, &s.serial})
      for (const Contact& c : *list) {
        std::uint32_t a = entity[c.a], b = entity[c.b];
        auto inserted = out.insert({std::min(a, b), std::max(a, b)});
        EXPECT_TRUE(inserted.second) << "pair listed twice: " << a << ", " << b;
      }
  return out;
}

PairSet contacts_with(World& w, NarrowphaseMode mode) {
  w.solver.narrowphase = mode;
  GridSystem grid;
  grid.run(w);
  NarrowphaseScratch scratch;
  find_contacts(w, scratch);
  return sphere_pairs(w);
}

void random_scene(World& w, unsigned seed, std::size_t n) {
  test::make_pit(w, 1.0f, 0.5f, 0.5f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f), y(0.05f, 0.8f), rad(0.02f, 0.06f), vel(-0.5f, 0.5f);
  std::uniform_real_distribution<float> fast(-30.0f, 30.0f);
  for (std::size_t i = 0; i < n; ++i) {
    // One sphere in twenty is fast enough to need the wide search.
    Vec3 v = i % 20 == 0 ? Vec3(fast(rng), fast(rng), fast(rng)) : Vec3(vel(rng), vel(rng), vel(rng));
    test::add_ball(w, Vec3(u(rng), y(rng), u(rng)), v, rad(rng));
  }
}

}  // namespace

TEST(Narrowphase, GridFindsExactlyTheContactSetOfTheNaiveReference) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    World grid_world, naive_world;
    random_scene(grid_world, seed, 1500);
    random_scene(naive_world, seed, 1500);
    PairSet by_grid = contacts_with(grid_world, NarrowphaseMode::Grid);
    PairSet by_naive = contacts_with(naive_world, NarrowphaseMode::Naive);
    EXPECT_GT(by_naive.size(), 500u) << "the scene should be crowded enough to test something";
    EXPECT_EQ(by_grid, by_naive) << "seed " << seed;
  }
}

TEST(Narrowphase, FindsExactlyThePairsWithinBothPairMargins) {
  World w;
  random_scene(w, 9, 800);
  PairSet found = contacts_with(w, NarrowphaseMode::Grid);
  auto x = w.spheres.position();
  auto v = w.spheres.velocity();
  auto r = w.spheres.radius();
  auto entity = w.spheres.entity_index();
  const float dt = w.step(), g = w.gravity().norm();
  std::size_t near_pairs = 0;
  for (std::uint32_t i = 0; i < w.spheres.size(); ++i)
    for (std::uint32_t j = i + 1; j < w.spheres.size(); ++j) {
      // The margins the narrowphase lists by are held to the cap (engine/speculative_margin.h).
      const float reach =
          r[i] + r[j] + capped_pair_margin(v[i].norm(), dt, g, r[i]) + capped_pair_margin(v[j].norm(), dt, g, r[j]);
      const float d = (x[i] - x[j]).norm();
      const std::uint32_t a = entity[i], b = entity[j];
      const bool listed = found.count({std::min(a, b), std::max(a, b)}) > 0;
      // Float slack at the boundary either way.
      if (d < reach * (1.0f - 1e-5f)) {
        ++near_pairs;
        EXPECT_TRUE(listed) << "missed " << a << "-" << b;
      }
      if (d > reach * (1.0f + 1e-5f)) {
        EXPECT_FALSE(listed) << a << "-" << b << " is out of reach";
      }
    }
  EXPECT_GT(near_pairs, 300u) << "the scene should be crowded enough to test something";
}

// The pair margins cover the one way gravity closes a pair: a ball falling onto one that is held
// up. Ball b rests on a ball on the floor; ball a falls onto it at 1 m/s from just under what one
// step of fall covers, v dt + g dt^2 / 2, and must be listed. (With no support both would fall
// alike, and gravity would not close the pair at all.) The balls are small enough for the drop's
// gravity term to exceed the minimum margins, which would otherwise cover it, and large enough
// for the drop (1.76 r) to be within the margin cap (2.5 r): a longer one is split into passes
// of the step (engine/step_passes.h), each within the cap.
TEST(Narrowphase, ABallFallingOntoAHeldBallIsFoundWithinOneStepsDrop) {
  const float r = 0.01f, speed = 1.0f;
  World w;
  test::make_pit(w, 1.0f, 0.5f, 0.5f);
  const float dt = w.step(), g = w.gravity().norm();
  const float drop = speed * dt + 0.5f * g * dt * dt;
  ASSERT_GT(0.5f * g * dt * dt, 2 * kMinMarginFraction * r);
  const Entity bottom = test::add_ball(w, Vec3(0, r, 0), Vec3::Zero(), r);
  const Entity held = test::add_ball(w, Vec3(0, 3 * r, 0), Vec3::Zero(), r);
  const Entity falling = test::add_ball(w, Vec3(0, 5 * r + 0.999f * drop, 0), Vec3(0, -speed, 0), r);
  const PairSet found = contacts_with(w, NarrowphaseMode::Grid);
  EXPECT_EQ(found, (PairSet{{bottom.index, held.index}, {held.index, falling.index}}));
}

TEST(Narrowphase, PlaneContactsOnlyNearTheFloorAndWalls) {
  World w;
  test::make_pit(w, 1.0f, 0.5f, 0.5f);
  Entity floor_ball = test::add_ball(w, Vec3(0, 0.04f, 0));
  test::add_ball(w, Vec3(0.5f, 0.5f, 0.5f));  // mid-air, far from every plane
  contacts_with(w, NarrowphaseMode::Grid);
  std::size_t statics = 0;
  for (const SlabContacts& s : w.contacts.slabs)
    for (const Contact& c : s.statics) {
      ++statics;
      EXPECT_EQ(c.b, kPlaneTag | 0u);  // the floor
      EXPECT_EQ(w.spheres.entity_at(c.a), floor_ball);
    }
  EXPECT_EQ(statics, 1u);
}

// Joint colliders are filtered by boxes before the exact segment test (systems/narrowphase.cpp):
// the filter must drop no contact the exact test makes. Spheres crowd around capsules of every
// orientation, some moving, with centres on both sides of every box face and many within a hair
// of the reach.
TEST(Narrowphase, EverySphereWithinReachOfAJointColliderGetsItsContactOnce) {
  World w;
  test::make_pit(w, 1.0f, 0.5f, 0.5f);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-0.6f, 0.6f), y(0.2f, 0.8f), len(-0.25f, 0.25f), rad(0.02f, 0.08f);
  std::uniform_real_distribution<float> vel(-3.0f, 3.0f);
  for (int k = 0; k < 12; ++k) {
    ColliderDesc d;
    d.shape = ColliderShape::Capsule;
    d.a = Vec3(u(rng), y(rng), u(rng));
    // Every fourth one is a sphere collider, and one capsule lies along each axis.
    d.b = k % 4 == 0 ? d.a : (k < 4 ? Vec3(d.a + Vec3::Unit(k - 1) * 0.2f) : Vec3(d.a + Vec3(len(rng), len(rng), len(rng))));
    d.radius = rad(rng);
    d.velocity_a = k % 2 ? Vec3(vel(rng), vel(rng), vel(rng)) : Vec3::Zero();
    d.velocity_b = d.velocity_a;
    w.colliders.add(d);
  }
  std::uniform_real_distribution<float> ball(0.02f, 0.04f), speed(-1.0f, 1.0f);
  for (int i = 0; i < 3000; ++i)
    test::add_ball(w, Vec3(u(rng), y(rng), u(rng)), Vec3(speed(rng), speed(rng), speed(rng)), ball(rng));
  contacts_with(w, NarrowphaseMode::Grid);

  std::set<std::pair<std::uint32_t, std::uint32_t>> found;  // (entity, collider)
  auto entity = w.spheres.entity_index();
  for (const SlabContacts& s : w.contacts.slabs)
    for (const Contact& c : s.statics) {
      if (!(c.b & kColliderTag)) continue;
      EXPECT_TRUE(found.insert({entity[c.a], c.b & ~kTagMask}).second) << "collider contact listed twice";
    }

  // The exact test, as the narrowphase makes it, for every sphere and collider.
  const ColliderTable& cols = w.colliders;
  auto x = w.spheres.position();
  auto v = w.spheres.velocity();
  auto r = w.spheres.radius();
  const float dt = w.step(), g = w.gravity().norm();
  std::size_t expected = 0, close_calls = 0;
  for (std::uint32_t i = 0; i < w.spheres.size(); ++i)
    for (std::uint32_t k = 0; k < cols.size(); ++k) {
      const float t = closest_segment_parameter(cols.a()[k], cols.b()[k], x[i]);
      const Vec3 q = cols.a()[k] + t * (cols.b()[k] - cols.a()[k]);
      const float margin = std::max(cols.velocity_a()[k].norm(), cols.velocity_b()[k].norm()) * dt;
      // Uncapped: a world with joint colliders runs whole steps (engine/step_passes.h).
      const float reach = r[i] + cols.radius()[k] + speculative_margin(v[i].norm(), dt, g, r[i]) + margin;
      const float d = (x[i] - q).norm();
      if (std::abs(d - reach) < 0.01f) ++close_calls;
      if ((x[i] - q).squaredNorm() >= reach * reach) {
        EXPECT_FALSE(found.count({entity[i], k})) << "ball " << entity[i] << " out of reach of collider " << k;
        continue;
      }
      ++expected;
      EXPECT_TRUE(found.count({entity[i], k})) << "missed ball " << entity[i] << " within reach of collider " << k;
    }
  EXPECT_EQ(found.size(), expected);
  EXPECT_GT(expected, 200u) << "the colliders should touch enough balls to test something";
  EXPECT_GT(close_calls, 50u) << "enough balls should lie within 1 cm of a collider's reach";
}

// The solver treats the spheres of a pile differently (systems/solver.cpp); the narrowphase marks
// them as it makes the contacts, from two threads at once, so the marks must be exactly the rows
// of the pairs (spanning slabs or not) that carried load.
TEST(Narrowphase, MarksExactlyTheRowsOfLoadedPairsAsPiled) {
  const FullTeams full;  // two threads, on rows that team_for might leave to one
  test::Sim s;
  test::make_pit(s.world, 0.5f, 0.0f, 0.5f);
  for (int i = 0; i < 2500; ++i)
    test::add_ball(s.world, Vec3(-0.44f + 0.0629f * (i % 15), 0.04f + 0.0801f * (i / 225), -0.44f + 0.0629f * (i / 15 % 15)));
  for (int i = 0; i < 10; ++i) test::add_ball(s.world, Vec3(-0.4f + 0.09f * i, 5.0f, 0.0f));  // still falling, alone
  s.start(2);
  s.step(40);  // a pile, some of it still settling: loaded and unloaded pairs both
  const std::size_t rows = s.world.spheres.size();
  std::vector<std::uint8_t> expected(rows, 0);
  std::size_t loaded = 0, unloaded = 0;
  for (const SlabContacts& sl : s.world.contacts.slabs)
    for (const auto* list : {&sl.pairs, &sl.serial})
      for (const Contact& c : *list) {
        if (!c.loaded_last_step()) {
          ++unloaded;
          continue;
        }
        ++loaded;
        expected[c.a] = expected[c.b] = 1;
      }
  ASSERT_GT(loaded, 100u);
  ASSERT_GT(unloaded, 0u);
  ASSERT_EQ(s.world.contacts.piled.size(), rows);
  EXPECT_EQ(s.world.contacts.piled, expected);
  EXPECT_GT(std::count(expected.begin(), expected.end(), 1), 100);
  EXPECT_LT(std::count(expected.begin(), expected.end(), 1), static_cast<std::ptrdiff_t>(rows));
}

TEST(Narrowphase, LastStepsImpulsesFollowTheirPairAcrossAReorder) {
  test::Sim s;
  test::make_pit(s.world, 0.5f, 0.0f, 0.5f);
  for (int i = 0; i < 40; ++i) test::add_ball(s.world, Vec3(-0.4f + 0.02f * i, 0.04f + 0.0801f * (i % 3), 0.0f));
  s.start();
  s.step(30);  // settle a little so contacts carry load
  // Run the grid and narrowphase of the next step by hand: every warm-started pair must be one
  // that had an impulse, keyed by the same two entities.
  // The solver left each loaded pair's impulse in the cache, under its generating row.
  std::map<std::pair<std::uint32_t, std::uint32_t>, float> before;
  auto entity = s.world.spheres.entity_index();
  const ContactSet& cache = s.world.contacts;
  for (std::size_t row = 0; row < entity.size(); ++row)
    for (std::uint32_t k = cache.warm_begin[row]; k < cache.warm_begin[row + 1]; ++k) {
      const WarmStartEntry& e = cache.warm[k];
      if (e.partner & kTagMask) continue;  // the floor, a wall
      before[{std::min(entity[row], e.partner), std::max(entity[row], e.partner)}] = e.normal_impulse;
    }
  ASSERT_GT(before.size(), 10u);
  GridSystem grid;
  grid.run(s.world);
  NarrowphaseScratch scratch;
  find_contacts(s.world, scratch);
  entity = s.world.spheres.entity_index();
  std::size_t carried = 0;
  for (const SlabContacts& sl : s.world.contacts.slabs)
    for (const Contact& c : sl.pairs) {
      auto key = std::make_pair(std::min(entity[c.a], entity[c.b]), std::max(entity[c.a], entity[c.b]));
      auto it = before.find(key);
      if (it == before.end()) {
        EXPECT_EQ(c.normal_impulse, 0.0f);
      } else {
        EXPECT_EQ(c.normal_impulse, it->second);
        ++carried;
      }
    }
  EXPECT_EQ(carried, before.size());
}

TEST(Narrowphase, AnImpulseCachedByThePartnerIsTurnedToTheNewContactsSide) {
  // Row order decides which sphere of a pair generates its contact, and rows are re-sorted every
  // step, so last step's contact may have had a and b the other way round. Its friction impulse
  // acted on its a as -F and on its b as +F; the new contact must apply the same pushes.
  test::Sim s;
  test::make_pit(s.world, 0.5f, 0.0f, 0.5f);
  test::add_ball(s.world, Vec3(-0.0399f, 0.04f, 0.0f));
  test::add_ball(s.world, Vec3(0.0399f, 0.04f, 0.0f));
  GridSystem grid;
  grid.run(s.world);
  NarrowphaseScratch scratch;
  find_contacts(s.world, scratch);
  std::vector<Contact> pairs;
  for (const SlabContacts& sl : s.world.contacts.slabs)
    for (const auto* list : {&sl.pairs, &sl.serial}) pairs.insert(pairs.end(), list->begin(), list->end());
  ASSERT_EQ(pairs.size(), 1u);
  const std::uint32_t a = pairs[0].a, b = pairs[0].b;

  // The cache as the partner's contact would have left it: under b's row, naming a's entity.
  const Vec3 on_cached_b(0.0f, 0.001f, 0.002f);  // pushed a (the cached contact's b) this way
  ContactSet& cs = s.world.contacts;
  cs.warm_begin.assign(s.world.spheres.size() + 1, 0);
  for (std::size_t k = b + 1; k < cs.warm_begin.size(); ++k) cs.warm_begin[k] = 1;
  cs.warm = {{s.world.spheres.entity_index()[a], 0.01f, on_cached_b}};

  grid.run(s.world);  // nothing moved: the rows stay as they are
  find_contacts(s.world, scratch);
  pairs.clear();
  for (const SlabContacts& sl : s.world.contacts.slabs)
    for (const auto* list : {&sl.pairs, &sl.serial}) pairs.insert(pairs.end(), list->begin(), list->end());
  ASSERT_EQ(pairs.size(), 1u);
  ASSERT_EQ(pairs[0].a, a) << "the test needs the same generating row as before";
  EXPECT_EQ(pairs[0].normal_impulse, 0.01f);
  // The new contact pushes its a by -friction_impulse: the same push a had before.
  EXPECT_TRUE(pairs[0].friction_impulse.isApprox(-on_cached_b)) << pairs[0].friction_impulse.transpose();
}
