// Contact solver: Box2D v3's soft step, with sub-steps. Each substep integrates velocities,
// re-applies the last substep's impulses (warm start), solves every contact once (or
// SolverSettings::solve_sweeps times) with a soft push-out bias (capped at push_out_speed), moves
// the spheres, and relaxes (solves again with no bias, so push-out never becomes bounce).
// Friction is Coulomb's at the contact point, plus, against a pit plane or joint collider, a
// spinning friction about the normal (a contact patch of kTwistArmFraction r,
// systems/batch_kernels.h). Impacts faster than the restitution threshold
// get their restitution when they happen, inside the substep, and the part of the substep
// before the impact is accounted for exactly (impact_shift), so a dropped ball returns to e^2
// of its height instead of losing a substep's worth of travel each bounce. After the last
// substep two guards hold what must hold whatever the contacts did: no sphere is left inside a
// joint collider, nor a centre past the pit's floor or walls.
//
// Reads: radii, inverse masses, sleep, rows, colliders, gravity, the grid (its last permutation:
// a sphere that falls asleep keeps its warm-start entries with sleepers, systems/solver.cpp).
// Writes: positions, velocities, angular velocities, contacts (the warm-start cache).
//
// Data: the solver copies the spheres into quads of its own (systems/solver_bodies.h) and packs
// each slab's pairs, and its spheres' pit-plane contacts, into batches of sixteen that share no
// sphere, a column per field (systems/contact_batches.h). One kernel (systems/contact_kernel.h)
// solves a batch in lanes (systems/lanes.h: 16 at once with AVX-512, 8 with AVX2, 4 on any CPU,
// the same bits on each) and a joint-collider contact alone. Batching keeps Gauss-Seidel's order
// exactly: every sphere meets its contacts in list order, so the batches give bit for bit what
// the same contacts solved one at a time in list order give (checked against the scalar solver
// they replaced: a frictionless 1,000-ball crowd, 30 steps, every position and velocity equal;
// with friction the spin is kept as r w, which rounds differently). The order is what keeps a
// jam calm: batches that ignored it filled more lanes and let 3 of 10 spawned crowds fling a
// ball faster than the push-out cap allows. Moving bodies in and out of lanes by transposes, not
// the arithmetic, is most of a batch's cost.
//
// Parallelism without graph colouring: contacts are listed per grid slab (engine/
// contact_set.h). Slabs of one parity never share a sphere, so each parity is one parallel
// sweep, over groups of such slabs packed together (one slab's list is too much of a chain to
// fill the lanes); then the pairs that span slabs. Each thread takes the same contiguous run of
// groups in every pass (engine/thread_share.h), so the bodies and batches it touches stay in
// its core's cache, and waits only for the other threads' groups beside the one it is about to
// solve, not for whole sweeps (a barrier ends each substep). The result is the same for any
// number of threads, any grouping and any instruction set.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/contact_set.h"
#include "engine/system.h"
#include "systems/batch_kernels.h"
#include "systems/contact_batches.h"
#include "systems/solver_bodies.h"

namespace ballpit {

class World;

// A joint-collider contact, solved one at a time, and what it changes while the step runs (the
// contact itself stays as the narrowphase found it).
struct ColliderContact {
  const Contact* contact;
  float normal_impulse;
  Vec3 friction_impulse;
  float impact_shift;  // (1+e) x gap of an impact this substep, undone after the move (m)
};

// Slabs of one parity, whose contacts share no sphere, packed and solved as one stream of
// batches (systems/contact_batches.h).
struct SlabGroup {
  std::vector<int> slabs;
  std::vector<std::vector<Contact>*> statics, pairs;  // the slabs' lists
  BatchList planes, pair_batches;
  std::vector<ColliderContact> colliders;  // among the statics, in list order
  // The other parity's groups [meets_first, meets_last) whose contacts or rows meet this
  // group's: those of the slabs beside each of its slabs. An odd group is swept after these in
  // each pass, and an even group after these in the pass before, and after no others, so a
  // thread need not wait for every thread's sweep to end (systems/solver.cpp, Step::sweep).
  int meets_first = 0, meets_last = 0;
};

// What the solver keeps between steps only to reuse its memory, and two choices that change no
// result, for tests to prove that they do not.
struct SolverScratch {
  const BatchKernels* kernels = nullptr;  // null: batch_kernels(), the fastest this CPU runs
  int slabs_per_group = 0;                // 0: as many as keep the lanes full and the threads busy
  bool integrate_in_sweeps = true;        // false: the substep's kick and move on equal shares of rows

  SolverBodies bodies;
  std::vector<SlabGroup> groups[2];  // of the even slabs, of the odd ones
  // Per parity, the contacts and the batches of groups [0, k) at k: what packing and the
  // passes split among threads.
  std::vector<std::size_t> contacts_before[2], batches_before[2];
  // Rows [even_group_rows[k], even_group_rows[k + 1]) belong to even group k's slabs and the
  // odd slab after each: together every row, so each thread kicks and moves its own rows in its
  // even sweep, just before it reaches them, instead of on a share of its own that all threads
  // must finish before any sweeps: eight fewer waits a step, each a wake-up of the team (the
  // 100k pour on 2 threads with passive waits: 36.9 to 35.9 ms a step; 10k: 6.04 to 5.37, when
  // each was a parallel region). Empty when the contacts' slabs are not the grid's (contacts
  // made by hand) or integrate_in_sweeps is off: the equal shares and their waits run then.
  std::vector<std::uint32_t> even_group_rows;
  // The pairs that span slabs: every slab's, in slab order, and their batches.
  std::vector<Contact> serial_pairs;
  BatchList serial;
  std::vector<std::uint32_t> last_batch;
  // Last step's warm-start cache, set aside while this step's is written (what a sphere that
  // fell asleep keeps comes from it), and the rows of those that fell asleep.
  std::vector<std::uint32_t> previous_warm_begin;
  std::vector<WarmStartEntry> previous_warm;
  std::vector<std::uint32_t> fell_asleep;
  // Where each row's next entry goes as the cache is filled. Kept, not made each step: a
  // buffer this size (4 bytes a sphere) comes fresh from mmap, and faults in page by page,
  // every step (ballpit sets glibc's mmap threshold, app/main.cpp).
  std::vector<std::uint32_t> warm_cursor;
};

// What the scratch holds: bodies, batches, the groups' lists, the last step's warm-start cache.
std::vector<MemoryItem> solver_held(const SolverScratch& scratch);

// Runs the substeps of one step over world.contacts (found by the narrowphase).
void solve_contacts(World& world, SolverScratch& scratch);
void solve_contacts(World& world);  // with scratch of its own

class SolverSystem : public System {
 public:
  std::string_view name() const override { return "solver"; }
  Access access() const override;
  void run(World& world) override { solve_contacts(world, scratch_); }
  bool data_parallel() const override { return true; }
  std::vector<MemoryItem> held() const override { return solver_held(scratch_); }

 private:
  SolverScratch scratch_;
};

}  // namespace ballpit
