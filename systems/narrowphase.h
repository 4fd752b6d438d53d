// Narrowphase: every sphere gathers the partners it may touch during the coming step (spheres
// from its neighbour cells, pit planes, joint colliders) into per-slab contact lists, and picks
// up last step's impulses for pairs that persist (warm starting).
// Reads: sphere positions, velocities, radii, materials, sleep, rows; grid; colliders.
// Writes: contacts (the lists, and the rows resting in a pile: ContactSet::piled).
// Decision: contacts are speculative. A pair is kept when its gap is below the sum of both
// spheres' margins (distance each can travel this step, relative to the other: pair_margin),
// so the solver can stop a fast sphere at the surface instead of finding it inside, or past,
// its partner next step. A margin is capped at kMostMarginFraction of the radius
// (engine/speculative_margin.h), which bounds what a sphere lists; motion too fast for the cap
// is split into passes of the step (engine/step_passes.h).
#pragma once

#include <cstdint>
#include <vector>

#include "engine/aligned_vector.h"
#include "engine/speculative_margin.h"
#include "engine/system.h"

namespace ballpit {

class World;

// Per-row values of this step, one column each (structure of arrays), so that the candidate
// test loads consecutive rows several at a time. Columns run a few rows past the last sphere
// so that such a load stays in bounds.
struct NarrowphaseScratch {
  Column<float> x, y, z;              // position (unit: m)
  Column<float> radius;               // (unit: m)
  Column<float> margin;               // speculative margin against spheres, pair_margin (unit: m)
  Column<std::uint32_t> flags;        // margin exceeds a one-cell search; asleep
  // Summary of the row's warm-start entries: bit partner_bit(p) is set for every partner p
  // they name, so a clear bit proves a pair absent (narrowphase.cpp). Made by last step's row
  // (the cache's order), then gathered into this step's.
  Column<std::uint32_t> cached_by_old_row, cached;
  // When the sleepers' rows of these columns were last made: after which of the grid's sorts
  // (SpatialGrid::sleepers_sorted), at a rebuild that kept them in place or not, for how many
  // rows. Made at a rebuild that kept them, they hold until the grid sorts them again.
  std::uint64_t sleepers_sorted = 0;
  bool made_kept = false;
  std::size_t made_rows = 0;
};

// Fills world.contacts from the current (grid-sorted) rows: an awake sphere owns its pairs with
// sleepers, which it finds in the grid's sleeper cells (engine/spatial_grid.h); a sleeper's
// row is never searched from. Deterministic for any thread count: each slab's lists depend
// only on its rows.
void find_contacts(World& world, NarrowphaseScratch& scratch);

class NarrowphaseSystem : public System {
 public:
  std::string_view name() const override { return "narrowphase"; }
  Access access() const override;
  void run(World& world) override { find_contacts(world, scratch_); }
  bool data_parallel() const override { return true; }
  std::vector<MemoryItem> held() const override;

 private:
  NarrowphaseScratch scratch_;
};

}  // namespace ballpit
