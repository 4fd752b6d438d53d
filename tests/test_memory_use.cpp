// The memory breakdown (engine/memory_use.h): every table a step fills reports what it holds,
// and the figures are the tables' own, not estimates.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "engine/list_capacity.h"
#include "engine/memory_use.h"
#include "systems/solver_bodies.h"
#include "tests/tiny_world.h"

namespace ballpit {
namespace {

std::size_t bytes_of(const std::vector<MemoryItem>& items, const std::string& table) {
  auto it = std::find_if(items.begin(), items.end(), [&](const MemoryItem& m) { return m.table == table; });
  EXPECT_NE(it, items.end()) << "no entry for " << table;
  return it == items.end() ? 0 : it->bytes;
}

TEST(MemoryUse, EveryTableAStepFillsSaysWhatItHolds) {
  test::Sim s;
  test::make_pit(s.world, 0.5f, 0.5f, 0.5f);
  for (int i = 0; i < 200; ++i)  // a loose column of balls, five a layer
    test::add_ball(s.world, Vec3(0.09f * static_cast<float>(i % 5) - 0.18f, 0.05f + 0.09f * static_cast<float>(i / 5), 0.0f));
  s.start();
  s.step(30);
  const std::vector<MemoryItem> items = memory_by_table(s.world, *s.scheduler);
  const std::size_t n = s.world.spheres.size();

  // The sphere columns: at least position, velocity, spin, radius, inverse mass, material, colour,
  // still time, sleep flag, entity and generation for every row; the reorder's scratch as much as
  // the widest column (one column is reordered through it at a time).
  const std::size_t row = 3 * sizeof(Vec3) + 3 * sizeof(float) + 2 + 3 * 4 + 1;
  EXPECT_GE(bytes_of(items, "spheres"), n * row);
  EXPECT_GE(bytes_of(items, "spheres: reorder targets"), n * sizeof(Vec3));

  // Lists hold at least the contacts the step found, and the solver batches them.
  const std::size_t contacts = s.world.contacts.count();
  ASSERT_GT(contacts, n);  // the balls rest on each other
  EXPECT_GE(bytes_of(items, "contact lists"), contacts * sizeof(Contact));
  EXPECT_GE(bytes_of(items, "warm-start cache"), s.world.contacts.warm.size() * sizeof(WarmStartEntry));
  EXPECT_GE(bytes_of(items, "solver: bodies"), n * sizeof(SolverBody));
  EXPECT_GT(bytes_of(items, "solver: batches"), 0u);
  EXPECT_GE(bytes_of(items, "grid"), n * sizeof(std::uint32_t));
  EXPECT_GT(bytes_of(items, "narrowphase: row columns"), 5 * n * sizeof(float));
}

// A list refilled every step gives back capacity only once it holds over twice what it needs,
// and then keeps a quarter more than the need, so a steady pit never reallocates.
TEST(MemoryUse, ListsGiveBackCapacityFromABusierStepOnly) {
  std::vector<Contact> list;
  list.reserve(10000);  // a peak: 320 KB
  release_excess_capacity(list, 5000);
  EXPECT_EQ(list.capacity(), 10000u);  // exactly twice the need: kept
  release_excess_capacity(list, 4000);
  EXPECT_EQ(list.capacity(), 5000u);  // 4000 + 4000 / 4
  EXPECT_TRUE(list.empty());

  std::vector<Contact> small;  // under kKeepSmallListBytes: left alone
  small.reserve(kKeepSmallListBytes / sizeof(Contact));
  release_excess_capacity(small, 0);
  EXPECT_EQ(small.capacity(), kKeepSmallListBytes / sizeof(Contact));
}

}  // namespace
}  // namespace ballpit
