// The uniform grid over the spheres, rebuilt every step by a counting sort (systems/grid.h).
// It spans the spheres' bounding box, not the pit: memory is O(N), never O(pit volume). A
// sphere outside the capped extent is clamped into the border cell, which keeps every true
// neighbour within one cell (clamping never pulls two cells apart), so the search stays exact.
// Where some spheres sleep, the awake rows come first and the sleepers after them, each part
// sorted by cell with a cell index of its own (cell_start's two halves): a step's passes over
// the awake spheres then skip the sleepers' rows whole (issue 39, systems/sleeping.h).
#pragma once

#include <cstdint>
#include <vector>

#include "engine/aligned_vector.h"
#include "engine/math.h"

namespace ballpit {

struct SpatialGrid {
  float cell_size = 0.0f;     // 2 * (largest radius + slow margin) (unit: m)
  float slow_margin = 0.0f;   // speculative margin covered by a one-cell search (unit: m)
  Vec3 origin = Vec3::Zero();  // corner of cell (0, 0, 0) (unit: m)
  int nx = 0, ny = 0, nz = 0;
  float max_radius = 0.0f;    // (unit: m)

  // Awake rows of cell k are [cell_start[k], cell_start[k + 1]); where the grid is split, its
  // sleepers are [cell_start[C + k], cell_start[C + k + 1]) with C = cell_count(). Keys run y
  // fastest, then z, then x.
  Column<std::uint32_t> cell_start;
  Column<std::uint32_t> cell_of_row;        // cell key of each (sorted) row, below cell_count()
  bool split = false;                       // sleepers sorted after the awake rows
  std::vector<std::uint32_t> new_to_old;    // the last rebuild's permutation
  bool kept_order = false;                  // the last step skipped the rebuild: new_to_old is the identity
  // The last full sort, by a stamp no other grid's sort shares, and the rebuilds since that
  // found no sleep changed and every sleeper in place, and kept their rows (systems/grid.h):
  // what a reader made of the sleepers' rows at one of those still holds for them.
  std::uint64_t sleepers_sorted = 0;
  std::uint32_t kept_since_sorted = 0;

  std::size_t cell_count() const { return static_cast<std::size_t>(nx) * ny * nz; }
  std::uint32_t key(int x, int y, int z) const {
    return static_cast<std::uint32_t>((x * nz + z) * ny + y);
  }
  int clamp_x(float p) const { return clamp_axis(p - origin.x(), nx); }
  int clamp_y(float p) const { return clamp_axis(p - origin.y(), ny); }
  int clamp_z(float p) const { return clamp_axis(p - origin.z(), nz); }
  int slab_of_key(std::uint32_t k) const { return static_cast<int>(k / (static_cast<std::uint32_t>(ny) * nz)); }
  // First awake row of slab x (x may equal nx: one past the last awake row).
  std::uint32_t slab_row_begin(int x) const { return cell_start[static_cast<std::size_t>(x) * ny * nz]; }
  // First sleeping row of slab x (x may equal nx: the table's end); an empty range unless split.
  std::uint32_t slab_sleeper_begin(int x) const {
    const std::size_t cells = cell_count();
    return split ? cell_start[cells + static_cast<std::size_t>(x) * ny * nz] : cell_start[cells];
  }
  // Rows [0, awake_rows()) are awake, the rest sleep.
  std::uint32_t awake_rows() const { return cell_start[cell_count()]; }

 private:
  // Clamps in float before converting: a cast of +inf or of a cell index past INT_MAX is
  // undefined, and NaN must land somewhere valid too (cell 0; the NaN guard reports it).
  int clamp_axis(float d, int n) const {
    float c = d / cell_size;
    if (!(c >= 0.0f)) return 0;
    if (c >= static_cast<float>(n - 1)) return n - 1;
    return static_cast<int>(c);
  }
};

}  // namespace ballpit
