// Contact solver: Box2D v3's soft step, with sub-steps. Each substep integrates velocities,
// re-applies last substep's impulses (warm start), solves every contact once with a soft
// push-out bias (capped at push_out_speed), moves the spheres, and relaxes (solves again with
// no bias, so push-out never becomes bounce). Impacts faster than the restitution threshold
// get their restitution when they happen, inside the substep, and the part of the substep
// before the impact is accounted for exactly (see Contact::impact_shift), so a dropped ball
// returns to e^2 of its height instead of losing a substep's worth of travel each bounce.
//
// Reads: radii, inverse masses, sleep, rows, colliders, gravity.
// Writes: positions, velocities, angular velocities, contacts (impulses, warm-start cache).
//
// Parallelism without graph colouring: contacts are listed per grid slab (engine/
// contact_set.h). Slabs of one parity never share a sphere, so each parity is one parallel
// sweep, Gauss-Seidel inside a slab; then the serial contacts. The result is the same for any
// number of threads.
//
// The contact loop computes in Packed3 (engine/packed3.h: a Vec3 in one SSE register, rounded
// exactly as Eigen rounds), which cuts its instructions by a third against Eigen's unaligned
// Vec3 and changes no bit of the result. What bounds it now is its instruction count, not the
// chain through a sphere shared by consecutive contacts: reordering each slab by a greedy
// colouring (no two contacts of a colour share a sphere, so the CPU may overlap them) cost the
// same (100k settled pile, 1 thread: 212 ms either way, not counting the 18 ms the colouring
// itself took), and making its data-dependent branches branchless did not help either.
//
// SIMD lanes need not change the result: take batches of four pairs from the front of a slab's
// list (a 32-pair window), a pair joining only once every earlier pair that shares a sphere
// with it is batched. Each sphere's pairs are then solved in list order and a batch's spheres
// are disjoint, so a batch solved at once is bit for bit the list (88% of lanes used). Tried on
// Relax with four AoS contacts in one AVX-512 register, one per 128-bit lane (branch
// wip/wide-relax), it kept every hash and saved nothing: settled 100k, 1 thread, 237-240 ms per
// step against 236-250 ms. Moving AoS contacts and spheres in and out of lanes (gathers,
// inserts, extracts) costs what the arithmetic saves, and the batch order alone, solved one by
// one, cost 274 ms. Eight lanes, gathered in and stored out by transposes, did no better
// (245-320 ms against 235-263 ms, three interleaved rounds). The next step is data already in
// lanes: contacts stored batch by batch, a column per field. (Code built for AVX-512 must also
// be built with -ffp-contract=off, or the scalar code inlined into it fuses multiply-adds and
// the hashes change.)
#pragma once

#include "engine/system.h"

namespace ballpit {

class World;

// Runs the substeps of one step over world.contacts (found by the narrowphase).
void solve_contacts(World& world);

class SolverSystem : public System {
 public:
  std::string_view name() const override { return "solver"; }
  Access access() const override;
  void run(World& world) override { solve_contacts(world); }
};

}  // namespace ballpit
