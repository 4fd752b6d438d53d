// The counting-sort grid: rows come out sorted by cell, stably, the same for any thread count,
// with cell ranges that hold exactly their spheres and memory bounded by N, not the pit.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <random>

#include "engine/spatial_grid.h"
#include "systems/grid.h"

using namespace ballpit;

namespace {

struct Cloud {
  std::vector<Vec3> x;
  std::vector<float> r;
};

Cloud random_cloud(std::size_t n, float extent, float height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent), y(0.0f, height), rad(0.01f, 0.05f);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.x.emplace_back(u(rng), y(rng), u(rng));
    c.r.push_back(rad(rng));
  }
  return c;
}

}  // namespace

TEST(Grid, RowsAreSortedStablyByCellAndCellRangesHoldTheirSpheres) {
  Cloud c = random_cloud(5000, 1.0f, 1.0f, 1);
  SpatialGrid g;
  GridScratch scratch;
  build_grid(g, c.x, c.r, scratch);
  ASSERT_EQ(g.new_to_old.size(), c.x.size());
  for (std::size_t row = 0; row < c.x.size(); ++row) {
    const Vec3& p = c.x[g.new_to_old[row]];
    std::uint32_t key = g.key(g.clamp_x(p.x()), g.clamp_y(p.y()), g.clamp_z(p.z()));
    ASSERT_EQ(g.cell_of_row[row], key);
    ASSERT_GE(row, g.cell_start[key]);
    ASSERT_LT(row, g.cell_start[key + 1]);
    if (row == 0) continue;
    ASSERT_LE(g.cell_of_row[row - 1], key);
    if (g.cell_of_row[row - 1] == key) {
      ASSERT_LT(g.new_to_old[row - 1], g.new_to_old[row]);  // stable within a cell
    }
  }
}

// Sleepers sort after every awake row, each part by cell, and the second half of cell_start
// indexes the sleepers' cells, so a pass over the awake spheres skips the sleepers' rows whole.
TEST(Grid, SleepersSortAfterTheAwakeRowsWithCellsOfTheirOwn) {
  Cloud c = random_cloud(5000, 1.0f, 1.0f, 3);
  std::vector<std::uint8_t> asleep(c.x.size());
  for (std::size_t i = 0; i < asleep.size(); ++i) asleep[i] = (i % 7) < 4;
  const std::size_t awake = static_cast<std::size_t>(std::count(asleep.begin(), asleep.end(), std::uint8_t{0}));
  SpatialGrid g;
  GridScratch scratch;
  build_grid(g, c.x, c.r, scratch, asleep);
  ASSERT_TRUE(g.split);
  ASSERT_EQ(g.awake_rows(), awake);
  ASSERT_EQ(g.cell_start.size(), 2 * g.cell_count() + 1);
  EXPECT_EQ(g.slab_row_begin(g.nx), awake);
  EXPECT_EQ(g.slab_sleeper_begin(0), awake);
  EXPECT_EQ(g.slab_sleeper_begin(g.nx), c.x.size());
  for (std::size_t row = 0; row < c.x.size(); ++row) {
    const std::uint32_t old = g.new_to_old[row];
    const bool sleeps = asleep[old] != 0;
    ASSERT_EQ(sleeps, row >= awake) << "row " << row;
    const Vec3& p = c.x[old];
    const std::uint32_t key = g.key(g.clamp_x(p.x()), g.clamp_y(p.y()), g.clamp_z(p.z()));
    ASSERT_EQ(g.cell_of_row[row], key);
    const std::size_t slot = key + (sleeps ? g.cell_count() : 0);
    ASSERT_GE(row, g.cell_start[slot]);
    ASSERT_LT(row, g.cell_start[slot + 1]);
    if (row > 0 && row != awake && g.cell_of_row[row - 1] == key) {
      ASSERT_LT(g.new_to_old[row - 1], old);  // stable within a cell
    }
  }
  // Without sleepers the grid is not split, and one index serves.
  build_grid(g, c.x, c.r, scratch, std::vector<std::uint8_t>(c.x.size(), 0));
  EXPECT_FALSE(g.split);
  EXPECT_EQ(g.cell_start.size(), g.cell_count() + 1);
  EXPECT_EQ(g.slab_sleeper_begin(0), c.x.size());
}

// A rebuild with no sleeper woken, fallen asleep or moved sorts only the awake rows; it must give
// exactly what the full sort gives, and a sleeper that moved or grew (a limb's guard, a user)
// must be sorted again, into its new cell. `asleep_of_every` rows in `every` sleep.
// `few`: whether the awake rows are few enough for sort_few_rows (systems/grid.cpp: an eighth of the cells).
void check_sleepers_keep_their_rows(std::size_t asleep_of_every, std::size_t every, bool few) {
  Cloud c = random_cloud(5000, 1.0f, 1.0f, 5);
  std::vector<std::uint8_t> asleep(c.x.size());
  for (std::size_t i = 0; i < asleep.size(); ++i) asleep[i] = (i % every) < asleep_of_every;
  SpatialGrid g;
  GridScratch scratch;
  // One rebuild, checked against a full sort of the same rows, and the rows put in its order,
  // with the sleepers kept, as GridSystem::run does.
  auto rebuild = [&](const char* what) {
    build_grid(g, c.x, c.r, scratch, asleep);
    SpatialGrid full;
    GridScratch fresh;
    build_grid(full, c.x, c.r, fresh, asleep);
    EXPECT_EQ(g.new_to_old, full.new_to_old) << what;
    EXPECT_TRUE(std::equal(g.cell_start.begin(), g.cell_start.end(), full.cell_start.begin(), full.cell_start.end())) << what;
    EXPECT_TRUE(std::equal(g.cell_of_row.begin(), g.cell_of_row.end(), full.cell_of_row.begin(), full.cell_of_row.end())) << what;
    Cloud sorted;
    std::vector<std::uint8_t> sorted_asleep;
    for (std::uint32_t old : g.new_to_old) {
      sorted.x.push_back(c.x[old]);
      sorted.r.push_back(c.r[old]);
      sorted_asleep.push_back(asleep[old]);
    }
    c = sorted;
    asleep = sorted_asleep;
    remember_sleepers(g, c.x, c.r, scratch);
  };
  rebuild("first");
  const std::size_t awake = g.awake_rows();
  ASSERT_GT(awake, 0u);
  EXPECT_EQ(awake < g.cell_count() / 8, few) << awake << " awake rows, " << g.cell_count() << " cells";
  // Awake spheres move into other cells (trading places, so that the grid's extent stays);
  // sleepers stay, and keep their rows, twice (the second rebuild finds them kept already).
  for (int round = 0; round < 2; ++round) {
    for (std::size_t i = 0; i + awake / 2 < awake; i += 3) std::swap(c.x[i], c.x[i + awake / 2]);
    rebuild("awake spheres moved");
    for (std::size_t i = awake; i < c.x.size(); ++i) ASSERT_EQ(g.new_to_old[i], i) << "a sleeper left its row";
    EXPECT_EQ(g.kept_since_sorted, static_cast<std::uint32_t>(round + 1)) << "the sleepers were not kept";
  }
  // A sleeper moved to another one's place: sorted again, into its new cell.
  const std::size_t moved = awake + 17;
  c.x[moved] = c.x[c.x.size() - 1];
  rebuild("a sleeper moved");
  EXPECT_EQ(g.kept_since_sorted, 0u) << "a sleeper moved, and the sleepers were kept";
  const std::size_t row = static_cast<std::size_t>(std::find(g.new_to_old.begin(), g.new_to_old.end(), moved) - g.new_to_old.begin());
  const Vec3& p = c.x[row];
  EXPECT_EQ(g.cell_of_row[row], g.key(g.clamp_x(p.x()), g.clamp_y(p.y()), g.clamp_z(p.z())));
  // A sleeper that grew past the largest radius changes the cells: sorted again.
  rebuild("kept again");
  ASSERT_EQ(g.kept_since_sorted, 1u);
  const float cell = g.cell_size;
  c.r[g.awake_rows() + 3] = 0.08f;  // the cloud's radii are at most 0.05
  rebuild("a sleeper grew");
  EXPECT_EQ(g.kept_since_sorted, 0u) << "a sleeper grew, and the sleepers were kept";
  EXPECT_GT(g.cell_size, cell);
}

TEST(Grid, SleepersThatStayPutKeepTheirRowsAndOneThatMovedIsSortedAgain) {
  check_sleepers_keep_their_rows(3, 5, false);  // 40% awake: the counting sort of the awake rows
}

TEST(Grid, AFewAwakeRowsAmongSleepersSortAsTheFullSortDoes) {
  check_sleepers_keep_their_rows(49, 50, true);  // 2% awake, far fewer than the cells: sort_few_rows
}

TEST(Grid, CellFitsTheLargestSphereAndItsMargin) {
  Cloud c = random_cloud(1000, 1.0f, 1.0f, 2);
  c.r[17] = 0.3f;  // one big sphere sets the cell for all
  SpatialGrid g;
  GridScratch scratch;
  build_grid(g, c.x, c.r, scratch);
  EXPECT_FLOAT_EQ(g.max_radius, 0.3f);
  EXPECT_GE(g.cell_size, 2.0f * 0.3f);
}

TEST(Grid, SameOrderForOneAndTwoThreads) {
  Cloud c = random_cloud(20000, 2.0f, 1.0f, 3);
  SpatialGrid one, two;
  GridScratch s1, s2;
  omp_set_num_threads(1);
  build_grid(one, c.x, c.r, s1);
  omp_set_num_threads(2);
  build_grid(two, c.x, c.r, s2);
  EXPECT_EQ(one.new_to_old, two.new_to_old);
}

TEST(Grid, MemoryIsBoundedBySphereCountNotByTheHeightTheyReach) {
  // A few spheres flung 20 m up must not make the grid as tall as the pit.
  Cloud c = random_cloud(1000, 0.5f, 0.5f, 4);
  c.x[0].y() = 20.0f;
  c.x[1].y() = 19.0f;
  SpatialGrid g;
  GridScratch scratch;
  build_grid(g, c.x, c.r, scratch);
  EXPECT_LE(g.cell_count(), std::max<std::size_t>(kCellsPerSphere * c.x.size(), 64));
  // Clamping keeps them findable: both land in the top row of cells.
  std::size_t row0 = 0, row1 = 0;
  for (std::size_t r = 0; r < c.x.size(); ++r) {
    if (g.new_to_old[r] == 0) row0 = r;
    if (g.new_to_old[r] == 1) row1 = r;
  }
  EXPECT_EQ(static_cast<int>(g.cell_of_row[row0] % g.ny), g.ny - 1);
  EXPECT_EQ(static_cast<int>(g.cell_of_row[row1] % g.ny), g.ny - 1);
}
