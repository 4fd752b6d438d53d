#include "systems/solver.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <utility>

#include "engine/error.h"
#include "engine/list_capacity.h"
#include "engine/memory_use.h"
#include "engine/thread_share.h"
#include "engine/world.h"
#include "systems/batch_kernels.h"
#include "systems/collider_guard.h"
#include "systems/contact_batches.h"
#include "systems/integrate.h"
#include "systems/sleep_regions.h"

// One contact at a time (planes, colliders) runs the lane kernel at T = float, compiled for
// the plain target like systems/batch_kernels_generic.cpp.
#define BALLPIT_LANES_TARGET generic
#include "systems/contact_kernel.h"

namespace ballpit {

namespace {

using generic::V3;
using StaticKernel = generic::ContactKernel<float, bool>;
using StaticState = generic::ContactState<float, bool>;

// Fewest contacts worth a thread of their own. Threads spinning: a settled pile of 1k spheres
// (3.7k contacts) solved in 0.81 ms on 1 thread and 0.92 ms on 2; one of 3k (11k) in 2.06 and
// 1.78 ms. Waiting passively, with a barrier between the parities and after every pass, each
// of which woke a thread, 2 threads paid only from 5k spheres (about 19k contacts); with waits
// only where groups meet (Step::sweep), the pour's solve over its first 5 s took 0.77 / 0.82 ms
// on 1 / 2 threads at 2k spheres, 1.17 / 1.03 at 3k and 1.99 / 1.42 at 5k.
constexpr PerThread kContactsPerThread{.spinning = 4096, .passive = 4096};

// Slabs packed into one stream of batches, and groups a thread (group_slabs).
constexpr int kMinSlabsPerGroup = 2;
constexpr int kMaxSlabsPerGroup = 8;
constexpr int kGroupsPerThread = 4;

// The calling thread's groups of one parity: contiguous runs of about equal cost (the cost of
// groups [0, k) at cost_before[k]: contacts when packing, batches in the passes), so each thread
// keeps its stretch of the pit, and its bodies and batches in its own cache, from pass to pass
// (engine/thread_share.h).
std::pair<int, int> group_share(const std::vector<std::size_t>& cost_before) {
  return thread_share(static_cast<int>(cost_before.size()) - 1,
                      [&](int k) { return cost_before[static_cast<std::size_t>(k)]; });
}

V3<float> xyz(const Quad& q) { return {q.x, q.y, q.z}; }
Quad quad(const V3<float>& v, float w) { return {v.x, v.y, v.z, w}; }
V3<float> v3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

// The solver's quads for the sphere table's rows, their state still to be loaded (load_rows),
// and the padding bodies after them: immobile, unit radius, 4 m apart in a row a million metres
// from any pit.
void size_bodies(const SphereTable& spheres, SolverBodies& bodies) {
  const std::size_t n = spheres.size();
  bodies.rows = n;
  bodies.awake_rows = row_spans(spheres.asleep()).awake_end;
  bodies.body.resize(n + SolverBodies::kPadRows);
  for (std::size_t k = n; k < n + SolverBodies::kPadRows; ++k) {
    bodies.body[k] = {{}, {}, {-1e6f - 4.0f * static_cast<float>(k - n), -1e6f, -1e6f, 1.0f}, {}};
  }
}

// Rows [first, last) of the sphere table's state into the solver's quads (systems/solver_bodies.h),
// with the step's mobility (0 while asleep: a sleeper acts as fixed) and spin as r w.
void load_rows(const SphereTable& spheres, SolverBodies& bodies, std::size_t first, std::size_t last) {
  auto x = spheres.position();
  auto v = spheres.velocity();
  auto r = spheres.radius();
  auto inv_mass = spheres.inv_mass();
  auto asleep = spheres.asleep();
  const bool angular = spheres.has_angular();
  auto w = angular ? spheres.angular_velocity() : std::span<const Vec3>{};
  for (std::size_t i = first; i < last; ++i) {
    SolverBody& b = bodies.body[i];
    b.velocity = {v[i].x(), v[i].y(), v[i].z(), asleep[i] ? 0.0f : inv_mass[i]};
    b.spin = angular ? Quad{r[i] * w[i].x(), r[i] * w[i].y(), r[i] * w[i].z(), 0.0f} : Quad{};
    b.position = {x[i].x(), x[i].y(), x[i].z(), r[i]};
    b.pseudo = {};
  }
}

// Deepest a sphere may be left in the pit's floor or walls at the end of a step, as a fraction
// of its radius: its centre stays in the pit. Impacts can leave a sphere about half a radius
// into a wall between steps, which the next step's contact bounces exactly (an elastic gas of
// 2,000, 10,000 steps: 0.26 r at 6 substeps, once 0.54 r at 8); a centre past the plane is
// no longer one of those.
constexpr float kPitGuardDepth = 1.0f;

// Pit guard, once after the last substep, as store_bodies writes the positions back: a sphere
// deeper than kPitGuardDepth in a pit plane is moved back to that depth, its centre onto the
// plane. The narrowphase finds a sphere's plane contacts within a margin for its speed, but
// push-out moves it too, at up to its cap: a crowd spawned inside itself pushes its bottom row
// down at the cap, and with no floor contact yet a ball went 1.55 r into the floor in one step
// (1,000 balls in a tenth of their room, 8 substeps). The pit is infinitely heavy and must win,
// as a collider must (guard_colliders). Only the position is corrected, and only as far as the
// bound: the next step's contact takes the rest, with its restitution.
Vec3 kept_in_pit(const Pit& pit, Vec3 x, float radius) {
  for (int k = 0; k < pit.plane_count(); ++k) {
    if (!pit.plane_applies(k, x)) continue;
    const Vec3 n = pit.plane_normal(k);
    const float excess = n.dot(x) - pit.plane_offset(k) - radius + kPitGuardDepth * radius;  // < 0: too deep
    if (excess < 0.0f) x -= excess * n;
  }
  return x;
}

// The awake rows, and the sleepers in `guarded` (rows the collider guard moved): no pass moves
// any other sleeper.
void store_bodies(const SolverBodies& bodies, std::span<const std::uint32_t> guarded, const Pit& pit,
                  SphereTable& spheres) {
  auto x = spheres.mut_position();
  auto v = spheres.mut_velocity();
  auto r = spheres.radius();
  const bool angular = spheres.has_angular();
  auto w = angular ? spheres.mut_angular_velocity() : std::span<Vec3>{};
  auto store = [&](std::size_t i) {
    const Quad &p = bodies.body[i].position, &u = bodies.body[i].velocity;
    x[i] = kept_in_pit(pit, Vec3(p.x, p.y, p.z), p.w);
    v[i] = Vec3(u.x, u.y, u.z);
    if (angular) {
      const Quad& s = bodies.body[i].spin;
      w[i] = Vec3(s.x / r[i], s.y / r[i], s.z / r[i]);
    }
  };
  const std::int64_t rows = static_cast<std::int64_t>(bodies.awake_rows);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < rows; ++i) store(static_cast<std::size_t>(i));
  for (std::uint32_t i : guarded)
    if (i >= bodies.awake_rows) store(i);
}

// What the threads that run the substeps share (solve_contacts).
struct SolverTeam {
  SolverTeam(int substeps, const std::vector<SlabGroup> (&groups)[2])
      : shifted(static_cast<std::size_t>(substeps)),
        group_swept{std::vector<std::atomic<int>>(groups[0].size()), std::vector<std::atomic<int>>(groups[1].size())} {}
  // Per substep: its Relax pass moved spheres by impact shifts (the kept frames are stale).
  std::vector<std::atomic<std::uint8_t>> shifted;
  // Threads through their odd groups, over the passes that end at a barrier.
  std::atomic<std::uint64_t> swept{0};
  // Per parity and group: the last pass (Step::pass_number) that swept it.
  std::vector<std::atomic<int>> group_swept[2];

  // Waits until the groups [first, last) of a parity are through pass `pass`. A short wait
  // spins; a long one (the other thread descheduled) yields the core.
  void wait_for(int parity, int first, int last, int pass) const {
    const std::vector<std::atomic<int>>& swept_by = group_swept[parity];
    for (int g = first; g < last; ++g)
      for (int spins = 0; swept_by[static_cast<std::size_t>(g)].load(std::memory_order_acquire) < pass; ++spins) {
        if (spins < kSpinsBeforeYield) relax_cpu();
        else std::this_thread::yield();
      }
  }

  static constexpr int kSpinsBeforeYield = 1 << 14;
  static void relax_cpu() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
};

// The state of one step's solve that is not the world's: bodies, batches, flags.
struct Step {
  World& world;
  SolverScratch& scratch;
  const BatchKernels& kernels;
  const bool spin;
  BatchPassArgs args;
  Vec3 gravity;
  // Time into the step at which joint colliders are posed (unit: s). A collider row holds its
  // pose at the step's start and the velocity that carries it to the animation's pose at the
  // end (systems/joint_colliders.h), so each substep sees it where it is at that moment: a fast
  // limb sweeps the step in substep-sized moves instead of jumping a whole step at once.
  float collider_time = 0.0f;
  SolverTeam* shared = nullptr;  // what the threads that run the substeps share
  int pass_number = 0;           // passes begun this step, this one included
  bool ended_at_barrier = true;  // the last pass ended at a barrier (so did the step's start)

  // A joint collider as seen by sphere row a: normal from the sphere into the collider, gap, and
  // the collider's surface velocity there.
  void collider_frame(std::uint32_t a, std::uint32_t b, StaticState& c) const {
    const Quad& xa = scratch.bodies.body[a].position;
    const Vec3 x(xa.x, xa.y, xa.z);
    const ColliderTable& colliders = world.colliders;
    const std::uint32_t k = b & ~kTagMask;
    const Vec3 ea = colliders.a()[k] + collider_time * colliders.velocity_a()[k];
    const Vec3 eb = colliders.b()[k] + collider_time * colliders.velocity_b()[k];
    const float t = closest_segment_parameter(ea, eb, x);
    const Vec3 d = ea + t * (eb - ea) - x;
    const float dist = d.norm();
    c.n = v3(dist > 1e-9f ? Vec3(d / dist) : Vec3(0.0f, -1.0f, 0.0f));
    c.gap = dist - xa.w - colliders.radius()[k];
    c.vb = v3((1.0f - t) * colliders.velocity_a()[k] + t * colliders.velocity_b()[k]);
  }

  // A contact with a joint collider: infinitely heavy, unspun, moved by the animation alone.
  template <ContactPass pass>
  void solve_collider(ColliderContact& collider, BatchPassResult& result) {
    const Contact& contact = *collider.contact;
    SolverBody& body = scratch.bodies.body[contact.a];
    StaticState c{};
    collider_frame(contact.a, contact.b, c);
    c.reach = -kWarmStartReach * body.position.w;
    c.va = xyz(body.velocity);
    c.ma = body.velocity.w;
    c.sa = xyz(body.spin);
    c.pushed_a = body.spin.w;
    if (pass == ContactPass::Solve) c.pa = xyz(body.pseudo);
    c.normal_impulse = collider.normal_impulse;
    c.friction_impulse = v3(collider.friction_impulse);
    c.friction = contact.friction;
    c.restitution = contact.restitution;
    c.impact_shift = collider.impact_shift;
    c.loaded_last_step = contact.loaded_last_step();
    c.free_pair = !world.contacts.piled[contact.a];  // a limb strikes no sphere in a pile, as a plane does not
    if (spin) run_static<pass, true>(c);
    else run_static<pass, false>(c);
    collider.normal_impulse = c.normal_impulse;
    collider.friction_impulse = Vec3(c.friction_impulse.x, c.friction_impulse.y, c.friction_impulse.z);
    body.velocity = quad(c.va, c.ma);
    body.spin = quad(c.sa, c.pushed_a);
    if (pass == ContactPass::Solve) body.pseudo = quad(c.pa, body.pseudo.w);
    if (pass == ContactPass::Relax && c.impact_shift != 0.0f) {
      Quad& x = body.position;
      x = quad(xyz(x) + c.impact_shift * c.n, x.w);
      c.impact_shift = 0.0f;
      result.shifted = true;
    }
    collider.impact_shift = c.impact_shift;
  }

  template <ContactPass pass, bool with_spin>
  void run_static(StaticState& c) const {
    if constexpr (pass == ContactPass::WarmStart) StaticKernel::warm_start<with_spin, false>(c);
    else StaticKernel::solve<pass, with_spin, true>(c, -dot(v3(gravity), c.n), args.params);
  }

  void run_batches(BatchKind kind, ContactPass pass, BatchList& list, BatchPassResult& result) {
    ContactBatch* begin = list.data();
    kernels.get(kind, pass, spin)(begin, begin + list.size(), scratch.bodies, args, result);
  }

  template <ContactPass pass>
  void solve_statics(SlabGroup& group, BatchPassResult& result) {
    run_batches(BatchKind::Planes, pass, group.planes, result);
    for (ColliderContact& c : group.colliders) solve_collider<pass>(c, result);
  }

  // A group's contacts: planes and colliders first, so the floor's support travels up a column
  // of pairs (sorted bottom-up) within one sweep; and last again when solving: pairs pushed a
  // sphere after its wall did, and the wall must have the last word or a crowd can squeeze a
  // sphere through it.
  template <ContactPass pass>
  void sweep_group(SlabGroup& group, BatchPassResult& result) {
    solve_statics<pass>(group, result);
    run_batches(BatchKind::Pairs, pass, group.pair_batches, result);
    if (pass == ContactPass::Solve) solve_statics<pass>(group, result);
  }

  // Rows [first, last): the substep's velocity kick before the warm start reaches them, the
  // move before the relax pass does (after every contact of the solve pass).
  template <ContactPass pass>
  void integrate_rows(std::uint32_t first, std::uint32_t last) {
    const SolverSettings& settings = world.solver;
    if constexpr (pass == ContactPass::WarmStart)
      integrate_velocities(scratch.bodies, first, last, gravity, args.params.h, settings);
    if constexpr (pass == ContactPass::Relax) integrate_positions(scratch.bodies, first, last, args.params.h, gravity);
  }

  // One pass, run by every thread of the solver's team: its even groups, then its odd groups,
  // then the pairs that span slabs (they may touch any row) on the last thread through its odd
  // groups. No two slabs swept at once share a sphere, so the result is the same for any number
  // of threads. Threads do not wait for each other's whole sweeps, only for the groups that meet
  // the one they are about to sweep (SlabGroup::meets_first): an odd group for those even groups
  // in the same pass, an even group for those odd groups in the pass before. Barriers between
  // the parities and between passes made whichever thread was through first wait for the other
  // every time, and with passive waits also woke it: on 2 threads waiting passively, the 100k
  // pour's settled solve took 22.5 ms a step with them and 21.8 without, the 10k pour's settled
  // step 4.04 and 3.37 ms (medians of 5 and 3 runs in turn). Each thread sweeps its even groups
  // last to first: its last ones are what the next thread's first odd groups wait for, its
  // first ones what the previous thread's last odd groups do. A pass still ends at a barrier
  // where the next one needs every thread's: after Relax (its impact shifts decide, for every
  // thread, whether the kept frames still hold), where pairs span slabs, and where rows are
  // integrated in equal shares rather than by group (SolverScratch::even_group_rows).
  template <ContactPass pass>
  void sweep(int sub) {
    const int number = ++pass_number;
    const bool by_group = !scratch.even_group_rows.empty();
    if constexpr (pass != ContactPass::Solve) {
      if (!by_group) {
        const auto [first, last] = equal_share(static_cast<int>(scratch.bodies.awake_rows));
        integrate_rows<pass>(static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(last));
#pragma omp barrier
      }
    }
    BatchPassResult result;
    {
      const auto [first, last] = group_share(scratch.batches_before[0]);
      for (int g = last - 1; g >= first; --g) {
        SlabGroup& group = scratch.groups[0][g];
        if (!ended_at_barrier) shared->wait_for(1, group.meets_first, group.meets_last, number - 1);
        // Group by group: the rows just kicked or moved are still in the core's cache when the
        // group's sweep reads them (a thread's whole share of a 100k pit is not).
        if (pass != ContactPass::Solve && by_group)
          integrate_rows<pass>(scratch.even_group_rows[g], scratch.even_group_rows[g + 1]);
        sweep_group<pass>(group, result);
        shared->group_swept[0][static_cast<std::size_t>(g)].store(number, std::memory_order_release);
      }
    }
    const auto [first, last] = group_share(scratch.batches_before[1]);
    for (int g = first; g < last; ++g) {
      SlabGroup& group = scratch.groups[1][g];
      shared->wait_for(0, group.meets_first, group.meets_last, number);
      sweep_group<pass>(group, result);
      shared->group_swept[1][static_cast<std::size_t>(g)].store(number, std::memory_order_release);
    }
    ended_at_barrier = pass == ContactPass::Relax || !scratch.serial.empty() || !by_group;
    if (!ended_at_barrier) return;
    // One barrier fewer than a `single` after a barrier: the last thread to arrive has seen every
    // other thread's sweep (acquire), and the others wait for it at the pass's end.
    const std::uint64_t arrived = shared->swept.fetch_add(1, std::memory_order_acq_rel) + 1;
    if (arrived % static_cast<std::uint64_t>(omp_get_num_threads()) == 0)
      run_batches(BatchKind::Pairs, pass, scratch.serial, result);
    if (result.shifted) shared->shifted[static_cast<std::size_t>(sub)].store(1, std::memory_order_relaxed);
#pragma omp barrier
  }
};

// How many groups a parity's `own` slabs are cut into: four a thread, at most eight slabs and at
// least two to a group, and a multiple of the team where that allows.
int group_count(int own, int threads, int slabs_per_group) {
  if (slabs_per_group > 0) return (own + slabs_per_group - 1) / slabs_per_group;
  const int enough = std::max(kGroupsPerThread * threads, (own + kMaxSlabsPerGroup - 1) / kMaxSlabsPerGroup);
  const int most = std::max(1, own / kMinSlabsPerGroup);
  const int wanted = (enough + threads - 1) / threads * threads;
  if (wanted <= most) return wanted;
  return most >= threads ? most / threads * threads : most;
}

// Slabs grouped by parity, a few to a group: enough slabs to fill the batches' lanes (one slab
// of a settled 100k pile fills 59% of them, four 90%, eight 97%) and enough groups, four a
// thread, for group_share to even out the threads' work. The groups are cut by contacts, not by
// slab count, and come in a multiple of the team: a thread can only take whole groups, and at
// 100k spheres ten groups of five slabs gave one of 2 threads 54% of the batches and 20% more
// time in the passes. The grouping does not change the result.
void group_slabs(World& world, SolverScratch& scratch) {
  std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const int count = static_cast<int>(slabs.size());
  const int threads = std::max(1, omp_get_max_threads());
  const int fixed = scratch.slabs_per_group;
  for (int parity = 0; parity < 2; ++parity) {
    const int own = (count - parity + 1) / 2;  // slabs parity, parity + 2, ...
    auto slab = [&](int j) -> SlabContacts& { return slabs[static_cast<std::size_t>(parity + 2 * j)]; };
    std::vector<std::size_t> slab_before(static_cast<std::size_t>(own) + 1, 0);  // contacts of slabs [0, j)
    for (int j = 0; j < own; ++j) slab_before[j + 1] = slab_before[j] + slab(j).pairs.size() + slab(j).statics.size();
    const int wanted = group_count(own, threads, fixed);
    std::vector<SlabGroup>& groups = scratch.groups[parity];
    std::vector<std::size_t>& before = scratch.contacts_before[parity];
    before.assign(1, 0);
    std::size_t used = 0;
    for (int g = 0; g < wanted; ++g) {
      const auto [first, last] =
          fixed > 0 ? std::pair(g * fixed, std::min(own, (g + 1) * fixed))
                    : share_of(g, wanted, own, [&](int j) { return slab_before[static_cast<std::size_t>(j)]; });
      if (first == last) continue;
      if (used == groups.size()) groups.emplace_back();
      SlabGroup& group = groups[used++];
      group.slabs.clear();
      group.statics.clear();
      group.pairs.clear();
      for (int j = first; j < last; ++j) {
        group.slabs.push_back(parity + 2 * j);
        group.statics.push_back(&slab(j).statics);
        group.pairs.push_back(&slab(j).pairs);
      }
      before.push_back(slab_before[static_cast<std::size_t>(last)]);
    }
    groups.resize(used);
  }
  // The groups each group meets: the other parity's groups holding the slabs beside its first
  // and last slab, and all between (groups are runs of slabs).
  std::vector<int> group_of(static_cast<std::size_t>(count), 0);
  for (const std::vector<SlabGroup>& groups : scratch.groups)
    for (std::size_t g = 0; g < groups.size(); ++g)
      for (int s : groups[g].slabs) group_of[static_cast<std::size_t>(s)] = static_cast<int>(g);
  // With two slabs or more, the slab before the first (after it, at the pit's start) and the one
  // after the last (before it, at the end) are of the other parity and in the grid.
  for (std::vector<SlabGroup>& groups : scratch.groups)
    for (SlabGroup& group : groups) {
      group.meets_first = group.meets_last = 0;  // a single slab meets nothing
      if (count < 2) continue;
      const int before = group.slabs.front() > 0 ? group.slabs.front() - 1 : group.slabs.front() + 1;
      const int after = group.slabs.back() + 1 < count ? group.slabs.back() + 1 : group.slabs.back() - 1;
      group.meets_first = group_of[static_cast<std::size_t>(before)];
      group.meets_last = group_of[static_cast<std::size_t>(after)] + 1;
    }
  // The even groups' awake rows, when the slabs are the grid's x slabs (engine/contact_set.h).
  std::vector<std::uint32_t>& rows = scratch.even_group_rows;
  rows.clear();
  const SpatialGrid& grid = world.grid;
  const std::size_t n = scratch.bodies.awake_rows;
  if (!scratch.integrate_in_sweeps || count == 0 || grid.nx != count ||
      grid.cell_start.size() != grid.cell_count() + 1 || grid.slab_row_begin(count) != n)
    return;
  rows.push_back(0);
  for (const SlabGroup& group : scratch.groups[0]) {
    if (grid.slab_row_begin(group.slabs.front()) != rows.back()) {  // not contiguous: no such rows
      rows.clear();
      return;
    }
    rows.push_back(grid.slab_row_begin(std::min(group.slabs.back() + 2, count)));
  }
  if (rows.back() != n) rows.clear();
}

// A group's joint-collider contacts, each with the impulses it starts the step from.
void list_colliders(SlabGroup& group) {
  for (const std::vector<Contact>* statics : group.statics)
    for (const Contact& c : *statics)
      if (c.b & kColliderTag) group.colliders.push_back({&c, c.normal_impulse, c.friction_impulse, 0.0f});
}

// The sphere table's state into the solver's bodies, each group's planes and pairs into
// batches, and the pairs that span slabs into batches of their own. One team does the first
// two: each parallel region wakes the team, which costs tens of microseconds where threads
// wait passively. Groups of one parity share the `last_batch` scratch: they hold no row in
// common, but groups of the other parity do, so the parities are packed one after the other.
void load_and_pack(World& world, SolverScratch& scratch) {
  const SphereTable& spheres = world.spheres;
  size_bodies(spheres, scratch.bodies);
  group_slabs(world, scratch);
  // Packing reads and writes only the awake rows' entries (systems/contact_batches.h).
  scratch.last_batch.resize(scratch.bodies.rows + SolverBodies::kPadRows);
  std::fill_n(scratch.last_batch.begin(), scratch.bodies.awake_rows, 0u);
  // Spheres resting in a pile (ContactSet::piled, marked by the narrowphase) get no exact-bounce
  // position correction (impact_shift) in their impacts with each other: moving a piled sphere by
  // a correction its neighbours do not share makes overlaps, whose push-out and impacts pumped
  // energy into piles (pour 4k at 3 substeps: 0.66 J left after 10 s with the correction, 0.0004 J
  // without). Nor does a pit plane strike them (systems/contact_kernel.h): their approach to it is
  // the pile's load.
  const std::vector<std::uint8_t>& piled = world.contacts.piled;
  if (piled.size() != scratch.bodies.rows)
    throw Error("solver: the contacts mark piled spheres for " + std::to_string(piled.size()) +
                " rows, the world has " + std::to_string(scratch.bodies.rows) + " (the narrowphase must run first)");
  const std::uint32_t awake_rows = static_cast<std::uint32_t>(scratch.bodies.awake_rows);
  const PackInput in{spheres.radius(), piled, world.pit, static_cast<std::uint32_t>(scratch.bodies.rows),
                     scratch.last_batch, 0, awake_rows};
  // A sleeper's body is read only where an awake sphere meets it: each group loads those of its
  // pairs as it packs them (no other group of its parity has their rows).
  auto load_sleepers = [&](std::span<std::vector<Contact>* const> lists) {
    for (const std::vector<Contact>* list : lists)
      for (const Contact& c : *list)
        if (c.b >= awake_rows && c.b < scratch.bodies.rows) load_rows(spheres, scratch.bodies, c.b, c.b + 1);
  };
  const bool colliders = world.colliders.size() > 0;
#pragma omp parallel
  {
    const auto [first, last] = equal_share(static_cast<int>(awake_rows));
    load_rows(spheres, scratch.bodies, static_cast<std::size_t>(first), static_cast<std::size_t>(last));
    for (int parity = 0; parity < 2; ++parity) {
      if (parity == 1) {
#pragma omp barrier
      }
      std::vector<SlabGroup>& groups = scratch.groups[parity];
      // Planes, then pairs, each with a stamp above every packing's before it.
      PackInput planes = in, pairs = in;
      planes.stamp = in.stamp + (2 * parity + 1) * kStampStride;
      pairs.stamp = in.stamp + (2 * parity + 2) * kStampStride;
      // Each thread packs about the stretch it will solve, into its own cache (the passes split
      // by batches, known only now, which moves at most a group between threads).
      const auto [first_group, last_group] = group_share(scratch.contacts_before[parity]);
      for (int g = first_group; g < last_group; ++g) {
        pack_planes(groups[g].statics, planes, groups[g].planes);
        pack_pairs(groups[g].pairs, pairs, groups[g].pair_batches);
        load_sleepers(groups[g].pairs);
        groups[g].colliders.clear();
        if (colliders) list_colliders(groups[g]);
      }
    }
  }
  for (int parity = 0; parity < 2; ++parity) {
    const std::vector<SlabGroup>& groups = scratch.groups[parity];
    std::vector<std::size_t>& before = scratch.batches_before[parity];
    before.assign(groups.size() + 1, 0);
    for (std::size_t g = 0; g < groups.size(); ++g)
      before[g + 1] = before[g] + groups[g].planes.size() + groups[g].pair_batches.size();
  }
  scratch.serial_pairs.clear();
  for (const SlabContacts& s : world.contacts.slabs)
    scratch.serial_pairs.insert(scratch.serial_pairs.end(), s.serial.begin(), s.serial.end());
  std::vector<Contact>* serial = &scratch.serial_pairs;
  PackInput spanning = in;
  spanning.stamp = in.stamp + 5 * kStampStride;
  pack_pairs({&serial, 1}, spanning, scratch.serial);
  load_sleepers({&serial, 1});
}

// A sleeper's pairs with other sleepers, its floor, walls and colliders are neither found nor
// solved, so it keeps their impulses as they were when it fell asleep (ContactSet::kept), and a
// region wakes carrying the load it carried (a sleeping pile of 1,000 woken whole: 2e-5 J a step
// later). Only what changed sleep since the last store is touched: a sphere that woke drops its
// kept entries; one that fell asleep keeps last step's entries with partners asleep now and with
// planes and colliders; the kept entries of the rest stay where they are. Copied into the per-row
// cache every step, they made a settled 100k pour with 173 balls awake cost 8.4 ms a step (the
// solver 5.7); kept apart, 3.8 (1.6), with the same state hash (Intel Xeon, 2 threads;
// profiling/reports/sleeping.md). The rows that sleep now are marked for the next step's lookups.
void keep_sleepers(World& world, SolverScratch& scratch) {
  ContactSet& cs = world.contacts;
  SleeperCache& kept = cs.kept;
  const SphereTable& spheres = world.spheres;
  const std::size_t n = spheres.size();
  auto entity = spheres.entity_index();
  auto asleep = spheres.asleep();
  const std::uint32_t store = ++cs.stores;
  const RowSpans spans = row_spans(asleep);
  // The kept spheres are those that slept at the last store, whose rows it marked: an awake row
  // whose row then was awake too has nothing to forget, and that byte, near its row, is read
  // instead of its entity's record, at random (where rows are not known, every one is looked up).
  const std::vector<std::uint32_t>& old_row = world.grid.new_to_old;
  const bool rows_known = old_row.size() == n;
  if (kept.sleepers > 0)
    for (std::size_t i = 0; i < spans.awake_end; ++i)
      if (!asleep[i] && !(rows_known && old_row[i] < cs.row_slept.size() && !cs.row_slept[old_row[i]])) kept.forget(entity[i]);
  const std::size_t sleepers = static_cast<std::size_t>(std::count(asleep.begin(), asleep.end(), std::uint8_t{1}));
  // Kept entries left are all of spheres that still sleep; any other sleeper fell asleep since.
  // A sleeper whose row slept at the last store is no such one: that byte, not its entity's
  // record, rules out most (a sleeper's row that did not sleep then, or that rows no longer
  // name after a sphere was removed, is looked up).
  if (sleepers > kept.sleepers) {
    std::vector<std::uint32_t>& fell = scratch.fell_asleep;
    auto find_fallen = [&](bool by_row) {
      fell.clear();
      for (std::size_t i = spans.asleep_begin; i < n; ++i) {
        if (!asleep[i]) continue;
        if (by_row && old_row[i] < cs.row_slept.size() && cs.row_slept[old_row[i]]) continue;
        if (!kept.asleep(entity[i])) fell.push_back(static_cast<std::uint32_t>(i));
      }
    };
    find_fallen(rows_known);
    if (fell.size() != sleepers - kept.sleepers) find_fallen(false);
    // All of them asleep first: an entry with a partner that fell asleep in the same step stays.
    for (std::uint32_t i : fell) kept.fall_asleep(entity[i], store);
    const std::vector<std::uint32_t>& old_begin = scratch.previous_warm_begin;
    for (std::uint32_t i : fell) {
      std::span<const WarmStartEntry> last;
      if (rows_known && old_row[i] + std::size_t{1} < old_begin.size())
        last = {scratch.previous_warm.data() + old_begin[old_row[i]], scratch.previous_warm.data() + old_begin[old_row[i] + 1]};
      kept.keep(entity[i], last);
    }
  }
  kept.compact();
  cs.row_slept.assign(asleep.begin(), asleep.end());
}

// Keeps each contact's impulses for the next step, keyed by its generating row and the
// partner's entity (rows move in the next grid rebuild; entities do not). They are read where the
// passes left them, in the batches (a joint collider's in its ColliderContact), not copied back
// into the contact lists first: in a one-substep solve of a 100k pile (bench_solver, 1 thread,
// perf) the copy and the two walks over the lists took 17% of the time, reading the batches 11%.
// Every row's entries are keyed by a distinct partner, so the order they are stored in, batch
// order, changes no lookup. Sleepers keep theirs apart (keep_sleepers).
void store_warm_start(World& world, SolverScratch& scratch) {
  ContactSet& cs = world.contacts;
  const std::size_t n = world.spheres.size();
  auto entity = world.spheres.entity_index();
  std::swap(cs.warm_begin, scratch.previous_warm_begin);
  std::swap(cs.warm, scratch.previous_warm);
  // Contacts belong to the rows that listed them, the awake ones (a sleeper lists nothing): only
  // those rows are counted and summed, and the sleepers' part of the index is filled with the
  // total, where a running sum over every row cost a settled 1M pit 1.5 ms a step. A contact
  // of another row (none should be) makes the count start again over every row.
  std::size_t counted = std::min(scratch.bodies.awake_rows, n);
  cs.warm_begin.resize(n + 1);
  std::fill_n(cs.warm_begin.begin(), counted + 1, 0u);
  // f(a, b, normal impulse, friction impulse) for every contact of a group that ends with a
  // normal impulse (> 0, so not NaN): only those are kept. A group's contacts belong to its own
  // rows, so groups count and fill independently, each on the thread that solved it, whose
  // cache still holds its batches.
  auto each_in_group = [](const SlabGroup& group, auto&& f) {
    for_each_loaded_contact(group.planes, f);
    for_each_loaded_contact(group.pair_batches, f);
    for (const ColliderContact& c : group.colliders)
      if (c.normal_impulse > 0.0f) f(c.contact->a, c.contact->b, c.normal_impulse, c.friction_impulse);
  };
  auto each = [&](auto&& f) {
#pragma omp parallel
    for (int parity = 0; parity < 2; ++parity) {
      const auto [first, last] = group_share(scratch.batches_before[parity]);
      for (int g = first; g < last; ++g) each_in_group(scratch.groups[parity][g], f);
    }
    for_each_loaded_contact(scratch.serial, f);  // rows of any slab: after the groups
  };
  std::atomic<bool> stray{false};
  auto count = [&](std::uint32_t a, std::uint32_t, float, const Vec3&) {
    if (a < counted) ++cs.warm_begin[a + 1];
    else stray.store(true, std::memory_order_relaxed);
  };
  each(count);
  if (stray.load()) {
    counted = n;
    std::fill(cs.warm_begin.begin(), cs.warm_begin.end(), 0u);
    each(count);
  }
  for (std::size_t i = 0; i < counted; ++i) cs.warm_begin[i + 1] += cs.warm_begin[i];
  std::fill(cs.warm_begin.begin() + static_cast<std::ptrdiff_t>(counted) + 1, cs.warm_begin.end(), cs.warm_begin[counted]);
  release_excess_capacity(cs.warm, cs.warm_begin[n]);  // two steps old: nothing in it is read
  cs.warm.resize(cs.warm_begin[n]);
  std::vector<std::uint32_t>& cursor = scratch.warm_cursor;
  cursor.assign(cs.warm_begin.begin(), cs.warm_begin.begin() + static_cast<std::ptrdiff_t>(counted));
  each([&](std::uint32_t a, std::uint32_t b, float normal, const Vec3& friction) {
    const std::uint32_t partner = (b & kTagMask) ? b : entity[b];
    cs.warm[cursor[a]++] = {partner, normal, friction};
  });
  keep_sleepers(world, scratch);
}

}  // namespace

std::vector<MemoryItem> solver_held(const SolverScratch& s) {
  const std::size_t kept = held_bytes(s.previous_warm_begin) + held_bytes(s.previous_warm) +
                           held_bytes(s.fell_asleep) + held_bytes(s.warm_cursor);
  std::size_t batches = held_bytes(s.serial), lists = held_bytes(s.serial_pairs) + held_bytes(s.last_batch) +
                                                      held_bytes(s.even_group_rows);
  for (int parity = 0; parity < 2; ++parity) {
    lists += held_bytes(s.groups[parity]) + held_bytes(s.contacts_before[parity]) + held_bytes(s.batches_before[parity]);
    for (const SlabGroup& g : s.groups[parity]) {
      batches += held_bytes(g.planes) + held_bytes(g.pair_batches);
      lists += held_bytes(g.slabs) + held_bytes(g.statics) + held_bytes(g.pairs) + held_bytes(g.colliders);
    }
  }
  return {{"bodies", held_bytes(s.bodies.body)},
          {"batches", batches},
          {"group lists", lists},
          {"last warm-start cache", kept}};
}

Access SolverSystem::access() const {
  Access a;
  a.reads = {ColumnId::SphereRadius, ColumnId::SphereInvMass, ColumnId::SphereSleep, ColumnId::SphereRows,
             ColumnId::Colliders,    ColumnId::Gravity,       ColumnId::Grid};
  a.writes = {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity,
              ColumnId::Contacts};
  return a;
}

void solve_contacts(World& world) {
  SolverScratch scratch;
  solve_contacts(world, scratch);
}

void solve_contacts(World& world, SolverScratch& scratch) {
  const ContactSet& found = world.contacts;
  const TeamSize team(team_for(found.count(), kContactsPerThread));
  SphereTable& spheres = world.spheres;
  const SolverSettings& settings = world.solver;
  const int substeps = settings.substeps;
  const float h = world.step() / static_cast<float>(substeps);
  const std::size_t rows = spheres.size();
  // A pit asleep whole does not move, and its cache stays as it fell asleep (systems/sleeping.h).
  if (all_asleep(spheres.asleep())) {
    world.contacts.wake_requests.clear();
    return;
  }

  load_and_pack(world, scratch);
  const bool sleepers = any_asleep(spheres.asleep());
  world.contacts.wake_requests.assign(rows, 0);

  Step step{world, scratch, scratch.kernels ? *scratch.kernels : batch_kernels(), spheres.has_angular(), {},
            world.gravity()};
  const float inv_h = 1.0f / h;
  step.args.params = {h, inv_h, settings.push_out_rate * inv_h, settings.push_out_speed, settings.restitution_threshold};
  step.args.wake_requests = sleepers ? world.contacts.wake_requests.data() : nullptr;
  step.args.wake_speed = kStruckWakeFactor * settings.wake_speed;
  for (int k = 0; k < 3; ++k) step.args.gravity[k] = world.gravity()[k];
  step.args.frames_current = false;  // new batches: no pass has computed a frame yet
  // One team for every substep, its passes divided by barriers: each start of a parallel region
  // is a wake-up of the team, which costs tens of microseconds where threads wait passively.
  // Every thread runs the whole loop on its own copy of the step's pass settings, which all
  // compute alike from what they share.
  SolverTeam team_state(substeps, scratch.groups);
  step.shared = &team_state;
#pragma omp parallel firstprivate(step)
  for (int sub = 0; sub < substeps; ++sub) {
    step.collider_time = static_cast<float>(sub) * h;  // colliders where the substep starts
    step.sweep<ContactPass::WarmStart>(sub);
    // The frames are now those of these positions, by the warm start or the last Relax, and
    // Solve keeps them (the reference mode has every pass compute its own).
    step.args.frames_current = settings.keep_pair_frames;
    for (int sweep = 0; sweep < settings.solve_sweeps; ++sweep) step.sweep<ContactPass::Solve>(sub);
    step.collider_time = static_cast<float>(sub + 1) * h;  // and where it ends, as the spheres now are
    step.sweep<ContactPass::Relax>(sub);
    step.args.frames_current = settings.keep_pair_frames && !team_state.shifted[static_cast<std::size_t>(sub)].load(std::memory_order_relaxed);
  }
  // The collider guard may move any sleeper a limb reaches: it reads every body.
  if (world.colliders.size() > 0) {
    const std::int64_t first = static_cast<std::int64_t>(scratch.bodies.awake_rows);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = first; i < static_cast<std::int64_t>(rows); ++i)
      load_rows(spheres, scratch.bodies, static_cast<std::size_t>(i), static_cast<std::size_t>(i) + 1);
  }
  const std::vector<std::uint32_t> guarded =
      guard_colliders(world.colliders, world.step(), spheres.position(), scratch.bodies);  // before the positions are stored
  store_bodies(scratch.bodies, guarded, world.pit, spheres);
  store_warm_start(world, scratch);
}

}  // namespace ballpit
