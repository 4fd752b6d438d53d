// Grid broadphase: rebuilt every step by a parallel counting sort of sphere rows by cell key
// (per-thread histograms, a prefix sum, a stable scatter), then the sphere table is permuted
// into that order so each cell, and each x slab of cells, is a contiguous row range. Sleepers
// sort after every awake row, by cell too (engine/spatial_grid.h).
// Reads: positions, radii, sleep state. Writes: every sphere column (the permutation) and the grid.
// Decision: the grid spans the spheres' bounding box with a capped cell count, not the pit,
// so memory is O(N) however tall the walls are.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "engine/math.h"
#include "engine/spatial_grid.h"
#include "engine/system.h"

namespace ballpit {

// The box of the finite positions and the largest radius (lo > hi: none counted yet).
struct GridBounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<float>::max());
  float max_radius = 0.0f;
  void add(const GridBounds& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
    max_radius = std::max(max_radius, b.max_radius);
  }
};

struct GridScratch {
  std::vector<std::uint32_t> histograms;  // threads x cells, reused between steps
  std::vector<std::uint32_t> keys;        // cell key of each unsorted row
  std::vector<std::uint32_t> order;       // the few awake rows' sort (row indices by key)
  // The sleepers in their rows as the last full sort left them, and their bounds
  // (remember_sleepers; empty: none kept, and the next rebuild sorts every row). A rebuild that
  // finds them unchanged measures and sorts only the awake rows.
  std::vector<Vec3> sleeper_positions;
  std::vector<float> sleeper_radii;
  GridBounds sleeper_bounds;  // measured at the first rebuild that keeps them
  bool sleeper_bounds_measured = false;
};

// Speculative margin a one-cell search covers, as a fraction of the largest radius. Larger
// means fewer spheres need the wide search but more candidates for every sphere.
inline constexpr float kSlowMarginFraction = 0.25f;
// Cells allowed per sphere before the grid's extent is capped (clamped).
inline constexpr std::size_t kCellsPerSphere = 2;

// Sorts rows by cell, sleepers (asleep[i] != 0; none if `asleep` is empty) after the awake
// rows: fills grid.cell_start, grid.cell_of_row (in sorted order) and grid.new_to_old. Stable,
// so the order is the same for any thread count. Where no sphere has woken or fallen asleep
// since the last rebuild and the sleepers are as remember_sleepers() kept them, only the awake
// rows are measured and sorted: the sleepers keep their rows (a settled pit's rebuild then costs
// what its awake spheres do, and a byte compare of the sleepers).
void build_grid(SpatialGrid& grid, std::span<const Vec3> positions, std::span<const float> radii,
                GridScratch& scratch, std::span<const std::uint8_t> asleep = {});
// After the rows are put in the grid's order (SphereTable::permute): keeps the sleepers' rows
// for the next build_grid to tell whether they stayed put, once per full sort.
void remember_sleepers(const SpatialGrid& grid, std::span<const Vec3> positions, std::span<const float> radii,
                       GridScratch& scratch);

class GridSystem : public System {
 public:
  std::string_view name() const override { return "grid"; }
  Access access() const override;
  void run(World& world) override;
  bool data_parallel() const override { return true; }
  std::vector<MemoryItem> held() const override;

 private:
  GridScratch scratch_;
};

}  // namespace ballpit
