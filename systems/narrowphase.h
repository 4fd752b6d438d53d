// Narrowphase: every sphere gathers the partners it may touch during the coming step (spheres
// from its neighbour cells, pit planes, joint colliders) into per-slab contact lists, and picks
// up last step's impulses for pairs that persist (warm starting).
// Reads: sphere positions, velocities, radii, materials, sleep, rows; grid; colliders.
// Writes: contacts (the lists, and the rows resting in a pile: ContactSet::piled).
// Decision: contacts are speculative. A pair is kept when its gap is below the sum of both
// spheres' margins (distance each can travel this step, relative to the other: pair_margin),
// so the solver can stop a fast sphere at the surface instead of finding it inside, or past,
// its partner next step.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/aligned_vector.h"
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
  // Per grid cell: a sphere in it sleeps. Only awake spheres near a sleeper look back for
  // sleeping partners (narrowphase.cpp), and most awake spheres are nowhere near one.
  std::vector<std::uint8_t> sleeper_in_cell;
};

// Every awake sphere lists neighbours within this fraction of its radius, however slow: a
// resting row must already know its touching pairs when a blow lands mid-step, or the blow
// cannot pass along it within the step (Newton's cradle). Touching is what it must cover: at
// 0.05 r a settled 100k pile listed 72,650 pairs (21%) 0.01 to 0.15 r apart that carried
// nothing and cost a lane in every pass; at 0.02 r its settled step is about 8% cheaper, and
// every case of profiling/reports/speed_error.md keeps its bound.
inline constexpr float kMinMarginFraction = 0.02f;

// Speculative margin of a sphere moving at `speed` for one step dt under gravity g, against
// another sphere: the distance it can cover, plus the minimum above, plus a quarter of g dt^2.
// Gravity moves both spheres alike, so a pair closes under it only where one sphere falls and
// the other is held up: by at most 1/2 g dt^2, half of which each side's margin covers.
float pair_margin(float speed, float dt, float gravity, float radius);

// What a margin against a pit plane or a joint collider adds to the pair margin: those do not
// fall with the sphere, so it covers the whole gravity drop twice over, for the velocity the
// sphere gains (g dt^2 in all).
float static_margin_extra(float dt, float gravity);

// The same sphere's margin against a pit plane or a joint collider.
float speculative_margin(float speed, float dt, float gravity, float radius);

// Fills world.contacts from the current (grid-sorted) rows. Deterministic for any thread
// count: each slab's lists depend only on its rows.
void find_contacts(World& world, NarrowphaseScratch& scratch);

class NarrowphaseSystem : public System {
 public:
  std::string_view name() const override { return "narrowphase"; }
  Access access() const override;
  void run(World& world) override { find_contacts(world, scratch_); }
  bool data_parallel() const override { return true; }

 private:
  NarrowphaseScratch scratch_;
};

}  // namespace ballpit
