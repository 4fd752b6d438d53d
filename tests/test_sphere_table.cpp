#include <gtest/gtest.h>

#include <numeric>

#include "engine/error.h"
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
