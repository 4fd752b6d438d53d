#include <gtest/gtest.h>

#include <numeric>

#include "engine/error.h"
#include "engine/thread_share.h"
#include "engine/world.h"
#include "tiny_world.h"

using namespace ballpit;

TEST(SphereTable, HandlesFollowEveryReorder) {
  World w;
  std::vector<Entity> e;
  for (int i = 0; i < 10; ++i) e.push_back(test::add_ball(w, Vec3(float(i), 0, 0)));
  std::vector<std::uint32_t> reverse(10);
  std::iota(reverse.rbegin(), reverse.rend(), 0u);
  w.spheres.permute(reverse);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(w.spheres.row(e[i]), 9u - i);
    EXPECT_EQ(w.spheres.position()[w.spheres.row(e[i])].x(), float(i));
  }
}

// Few rows moving take permute()'s other path (only those rows are copied), as a settled pit's
// reorders do; every sphere must still be found with all of its own values.
TEST(SphereTable, AReorderThatMovesFewRowsKeepsEveryColumnWithItsEntity) {
  const TeamSize team(2);
  World w;
  std::vector<Entity> e;
  for (int i = 0; i < 100; ++i)
    e.push_back(test::add_ball(w, Vec3(float(i), 0, 0), Vec3(0, float(i), 0), 0.001f * float(i + 1)));
  std::vector<std::uint32_t> order(100);
  std::iota(order.begin(), order.end(), 0u);
  std::swap(order[3], order[4]);  // a swap within the first thread's share
  std::swap(order[10], order[90]);  // one across both shares
  order[50] = 51, order[51] = 52, order[52] = 50;  // a cycle of three
  for (int pass = 0; pass < 2; ++pass) {  // and back: the inverse moves the same rows
    w.spheres.permute(order);
    for (int i = 0; i < 100; ++i) {
      const std::uint32_t row = w.spheres.row(e[i]);
      EXPECT_EQ(w.spheres.position()[row].x(), float(i));
      EXPECT_EQ(w.spheres.velocity()[row].y(), float(i));
      EXPECT_EQ(w.spheres.radius()[row], 0.001f * float(i + 1));
      EXPECT_EQ(w.spheres.entity_at(row), e[i]);
    }
    std::vector<std::uint32_t> inverse(100);
    for (std::uint32_t k = 0; k < 100; ++k) inverse[order[k]] = k;
    order = inverse;
  }
  for (int i = 0; i < 100; ++i) EXPECT_EQ(w.spheres.row(e[i]), static_cast<std::uint32_t>(i));
}

// The header's promise: while the sphere count holds, a reorder leaves every column in its
// buffer (the API's spans and the Python module's arrays view them across steps), on both of
// permute()'s paths: all rows moving (a rotation) and few (one swap).
TEST(SphereTable, AReorderKeepsEveryColumnWhereItIs) {
  const TeamSize team(2);
  World w;
  w.enable_angular(true);
  std::vector<Entity> e;
  for (int i = 0; i < 100; ++i) e.push_back(test::add_ball(w, Vec3(float(i), 0, 0)));
  const SphereTable& s = w.spheres;
  auto addresses = [&] {
    return std::vector<const void*>{s.position().data(), s.velocity().data(), s.angular_velocity().data(),
                                    s.radius().data(),   s.inv_mass().data(), s.material().data(),
                                    s.color().data(),    s.still_time().data(), s.asleep().data(),
                                    s.entity_index().data()};
  };
  const std::vector<const void*> before = addresses();
  std::vector<std::uint32_t> rotation(100), swap(100);
  for (std::uint32_t k = 0; k < 100; ++k) rotation[k] = (k + 1) % 100;
  std::iota(swap.begin(), swap.end(), 0u);
  std::swap(swap[10], swap[90]);
  for (int pass = 0; pass < 3; ++pass) {  // an odd count: a swap of buffers would show
    w.spheres.permute(rotation);
    EXPECT_EQ(addresses(), before) << "after rotation " << pass;
    w.spheres.permute(swap);
    EXPECT_EQ(addresses(), before) << "after swap " << pass;
  }
  for (int i = 0; i < 100; ++i) EXPECT_EQ(s.position()[s.row(e[i])].x(), float(i));
}

TEST(SphereTable, ReordersBetweenAddsAndRemovesKeepEveryColumnWithItsEntity) {
  // permute() gathers into columns it keeps from the last reorder: they must take the table's
  // size each time, and leave nothing of the last reorder's rows behind.
  const TeamSize team(2);
  World w;
  std::vector<Entity> e;
  auto add = [&](int i) {
    e.push_back(test::add_ball(w, Vec3(float(i), 0, 0), Vec3(0, float(i), 0), 0.01f * float(i + 1)));
  };
  auto rotate = [&] {  // row k takes row k + 1's sphere
    const std::uint32_t n = static_cast<std::uint32_t>(w.spheres.size());
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t k = 0; k < n; ++k) order[k] = (k + 1) % n;
    w.spheres.permute(order);
  };
  for (int i = 0; i < 8; ++i) add(i);
  rotate();
  for (int i = 8; i < 20; ++i) add(i);  // larger than the kept columns
  rotate();
  w.remove_sphere(e[3]);
  w.remove_sphere(e[11]);  // smaller again
  rotate();
  rotate();
  EXPECT_EQ(w.spheres.size(), 18u);
  for (int i = 0; i < 20; ++i) {
    if (i == 3 || i == 11) {
      EXPECT_FALSE(w.spheres.contains(e[i]));
      continue;
    }
    const std::uint32_t row = w.spheres.row(e[i]);
    EXPECT_EQ(w.spheres.position()[row].x(), float(i));
    EXPECT_EQ(w.spheres.velocity()[row].y(), float(i));
    EXPECT_EQ(w.spheres.radius()[row], 0.01f * float(i + 1));
    EXPECT_EQ(w.spheres.entity_at(row), e[i]);
  }
}

TEST(SphereTable, RemovingMovesTheLastRowAndKeepsItsHandle) {
  World w;
  Entity a = test::add_ball(w, Vec3(1, 0, 0));
  Entity b = test::add_ball(w, Vec3(2, 0, 0));
  Entity c = test::add_ball(w, Vec3(3, 0, 0));
  w.remove_sphere(a);
  EXPECT_EQ(w.spheres.size(), 2u);
  EXPECT_FALSE(w.spheres.contains(a));
  EXPECT_EQ(w.spheres.position()[w.spheres.row(c)].x(), 3.0f);
  EXPECT_EQ(w.spheres.position()[w.spheres.row(b)].x(), 2.0f);
  EXPECT_THROW(w.spheres.row(a), Error);
}

TEST(SphereTable, AngularColumnExistsOnlyWhenEnabled) {
  World w;
  test::add_ball(w, Vec3::Zero());
  EXPECT_TRUE(w.spheres.angular_velocity().empty());
  w.enable_angular(true);
  EXPECT_EQ(w.spheres.angular_velocity().size(), 1u);
}

TEST(SphereTable, StoresInverseMass) {
  World w;
  Entity a = test::add_ball(w, Vec3::Zero(), Vec3::Zero(), 0.04f, 0.05f);
  EXPECT_FLOAT_EQ(w.spheres.inv_mass()[w.spheres.row(a)], 20.0f);
}
