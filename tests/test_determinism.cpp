// Same scene, same inputs: bit-identical state for any thread count and any run.
#include <gtest/gtest.h>
#include <omp.h>

#include "engine/pour_scene.h"
#include "engine/state_hash.h"
#include "engine/thread_share.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {

std::uint64_t pour_hash(int threads, int steps, std::size_t n) {
  omp_set_num_threads(threads);
  const FullTeams full;  // every system on every thread, whatever team_for would choose
  test::Sim s;
  PourScene scene;
  scene.spheres = n;
  scene.build(s.world);
  s.start(threads);
  s.step(steps);
  return state_hash(s.world);
}

}  // namespace

TEST(Determinism, OneAndTwoThreadsGiveTheSameStateHashAfterSixHundredPourSteps) {
  // 3000 balls: enough slabs (18) for both threads to take part in every sweep; FullTeams runs
  // every system on both, as small work would not.
  std::uint64_t one = pour_hash(1, 600, 3000);
  std::uint64_t two = pour_hash(2, 600, 3000);
  EXPECT_EQ(hash_hex(one), hash_hex(two));
}

TEST(Determinism, RepeatedRunsGiveTheSameStateHash) {
  EXPECT_EQ(pour_hash(2, 120, 3000), pour_hash(2, 120, 3000));
}

TEST(Determinism, TheHashSeesEveryBit) {
  test::Sim s;
  test::make_pit(s.world, 1.0f, 0.5f, 0.5f);
  Entity e = test::add_ball(s.world, Vec3(0, 1, 0));
  std::uint64_t before = state_hash(s.world);
  Vec3& p = s.world.spheres.mut_position()[s.world.spheres.row(e)];
  p.x() = std::nextafter(p.x(), 1.0f);
  EXPECT_NE(state_hash(s.world), before);
}
