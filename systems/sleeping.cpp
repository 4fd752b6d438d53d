#include "systems/sleeping.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/thread_share.h"
#include "engine/world.h"
#include "systems/sleep_regions.h"

namespace ballpit {

namespace {

// Rows worth a thread of their own: the passes spend a few nanoseconds a row, and with passive
// waits a second thread costs tens of microseconds to wake. A real pile's sleep update costs
// more than a packed lattice's (bench_sleeping: 0.18 ms at 100k on one thread): its contact
// pass reads every contact while some sphere sleeps. The sleeping pour's first 300 steps on 2
// threads (Intel Xeon): at 131,072 rows a thread, 100k ran the update on one, 2.47 ms a step
// (1.07 on two) and the wake 0.11 ms (0.05); at 40k 0.58 ms on one, 0.32 on two.
constexpr std::size_t kRowsPerThread = 16384;

// A region sleeps only with every contact of its awake spheres within this overlap, as a
// fraction of the smaller radius: the bound a settled pile holds without sleeping (shared/
// SCENES.md, 1% r). Still but not yet pushed apart, a region would keep its overlap for as long
// as it sleeps (the 1,000-ball pour slept with a pair 1.18% r deep).
constexpr float kSleepOverlapFraction = 0.01f;
// A sphere is still only while it stays within this fraction of its radius of where its still
// time began, whatever its speed: a pile that still compacts creeps at under sleep_speed, and a
// region that fell asleep creeping froze the pile loose. The 100k sleeping pour then slid and
// fell in avalanches after it had settled (balls at 0.6 to 1.9 m/s, 0.127 J and 0.06 r at the
// end against 0.003 J and 0.005 r without sleeping); at a tenth of a radius it ends at 0.001 J
// and 0.009 r with 1,700 balls awake; at a twentieth most of it creeps awake past 10 s
// (profiling/reports/sleeping.md). Speeds alone cannot tell creep from the solver's jitter,
// which a drift from a fixed point ignores.
constexpr float kStillDriftFraction = 0.1f;

// A sleeper pressed deeper than this by an awake sphere wakes: twice the bound above, so that a
// region that fell asleep near the bound is not woken by the last settling of the regions
// around it (at once the bound, a stirred corner kept waking regions 1.5 m away, one after the
// other, each pressed a hair past 1% r by the one before as it settled).
constexpr float kPressedWakeFraction = 2.0f * kSleepOverlapFraction;
// A sleeper pressed past the bound itself wakes when the sphere pressing it has been still for
// sleep_time: that is a jam, not a passing blow, and only the sleeper can free it by yielding.
// Without it, a ball that came to rest jammed against sleepers kept its overlap and held its
// region awake (the 100k sleeping pour ended with a pair 1.34% r deep with the approach wake
// at kApproachWakeFactor 2; 0.94% with this rule). A presser still for sleep_time is no longer
// settling, so the chain of the stirred corner above does not start again.

// Several threads may mark one region; every write stores the same value, so the outcome is
// deterministic, and atomic_ref keeps it free of data races.
void set_mark(std::uint8_t& mark) { SleepRegions::mark(mark); }

// The largest radius: the grid's, measured at its last rebuild, or the table's before the first.
float largest_radius(const World& world) {
  if (world.grid.max_radius > 0.0f) return world.grid.max_radius;
  auto r = world.spheres.radius();
  return r.empty() ? 0.0f : *std::max_element(r.begin(), r.end());
}

SleepRegions regions_of(const World& world) { return {world.pit, world.gravity(), largest_radius(world)}; }

// Lowers the level of every region that a moving awake sphere or a moving joint collider may
// reach within the coming step to the bottom of what it may reach: the box of the mover's
// travel, grown by its radius, the largest sphere's and the drop under gravity (a sleeper's
// centre in the box is all a touch needs). A sphere counts as moving above `sphere_speed`; a
// collider whenever it moves: a limb is as fixed as a sleeper, and one slower than the wake
// speed went through a sleeping ball instead of pushing it (0.45 r deep at 1 cm/s).
void mark_motion(const World& world, const SleepRegions& regions, float sphere_speed, Levels& levels) {
  const SphereTable& spheres = world.spheres;
  auto x = spheres.position();
  auto v = spheres.velocity();
  auto r = spheres.radius();
  auto asleep = spheres.asleep();
  const float dt = world.step();
  const float wake2 = sphere_speed * sphere_speed;
  const float reach = largest_radius(world) + world.gravity().norm() * dt * dt;
  const std::int64_t n = static_cast<std::int64_t>(row_spans(asleep).awake_end);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i] || !(v[i].squaredNorm() > wake2)) continue;  // NaN speeds are the guard's
    const Vec3 grow = Vec3::Constant(r[i] + reach + v[i].norm() * dt);
    regions.lower_box(x[i] - grow, x[i] + grow, levels);
  }
  const ColliderTable& colliders = world.colliders;
  auto ca = colliders.a();
  auto cb = colliders.b();
  auto cr = colliders.radius();
  for (std::size_t c = 0; c < colliders.size(); ++c) {
    const float speed = colliders.speed(c);
    if (!(speed > 0.0f)) continue;
    const Vec3 grow = Vec3::Constant(cr[c] + reach + speed * dt);
    regions.lower_box(ca[c].cwiseMin(cb[c]) - grow, ca[c].cwiseMax(cb[c]) + grow, levels);
  }
}

// What the step's contacts say, in one pass over them:
// - pressed (when some sphere sleeps): the wake level of every sleeper that an awake sphere
//   presses deeper than kPressedWakeFraction, or deeper than the bound after being still for
//   sleep_time (a jam, above), a region's width under it. A sleeper cannot yield, and a sphere
//   caught between it and a limb or a moving crowd would be squeezed into it for as long as it
//   sleeps.
// - deep (when `deep` is given): the restless level of both spheres of every contact deeper
//   than kSleepOverlapFraction, and of the regions next to those, a region's width under it. A deep
//   pair left awake among sleepers that cannot yield stays as deep for good (the 10k pour kept
//   three pairs 1.0 to 1.5% r deep, awake and still for 6 s, against 0.16% at most with
//   sleeping off). Planes count; colliders do not (a limb pressing on a ball keeps its region
//   awake by its motion, mark_motion). Only contacts whose first sphere lies in a region of
//   `near` are looked at for this: the regions within two tiles of one that could fall asleep,
//   which holds every region a mark could matter to (a partner is nearer than a region's width).
//   While a pit pours, or a crowd moves, few are, and the pass skips their contacts unread.
void mark_contacts(const World& world, const SleepRegions& regions, bool sleepers, Levels& pressed,
                   const std::vector<std::uint8_t>* near, Levels* deep) {
  auto x = world.spheres.position();
  auto still = world.spheres.still_time();
  const float sleep_time = world.solver.sleep_time;
  auto r = world.spheres.radius();
  auto asleep = world.spheres.asleep();
  const Pit& pit = world.pit;
  const Vec3 around = Vec3::Constant(regions.width);
  // Is the overlap deeper than `fraction` of the smaller radius? Colliders count as never.
  auto deeper = [&](const Contact& c, float fraction) {
    if (c.b & kColliderTag) return false;
    if (c.b & kPlaneTag) {
      const int p = static_cast<int>(c.b & ~kTagMask);
      return pit.plane_normal(p).dot(x[c.a]) - pit.plane_offset(p) < (1.0f - fraction) * r[c.a];
    }
    const float reach = r[c.a] + r[c.b] - fraction * std::min(r[c.a], r[c.b]);
    return (x[c.a] - x[c.b]).squaredNorm() < reach * reach;
  };
  // A sphere's contacts lie together in a list, so its region is looked up once for them all.
  struct Cursor {
    std::uint32_t row = ~0u;
    bool near = false;
  };
  auto check = [&](const Contact& c, Cursor& at) {
    if (near && c.a != at.row) at = {c.a, (*near)[regions.of(x[c.a])] != 0};
    const bool pair = !(c.b & kTagMask);
    const bool press = sleepers && pair && asleep[c.a] != asleep[c.b];
    if (!(press || at.near) || !deeper(c, kSleepOverlapFraction)) return;  // most contacts
    if (press) {
      const std::uint32_t sleeper = asleep[c.a] ? c.a : c.b, presser = asleep[c.a] ? c.b : c.a;
      if (still[presser] >= sleep_time || deeper(c, kPressedWakeFraction))
        SleepRegions::lower(pressed[regions.of(x[sleeper])], regions.wake_level_under(x[sleeper]));
    }
    if (at.near) {
      regions.lower_box(x[c.a] - around, x[c.a] + around, *deep);
      if (pair) regions.lower_box(x[c.b] - around, x[c.b] + around, *deep);
    }
  };
  const std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const int count = static_cast<int>(slabs.size());
#pragma omp parallel for schedule(dynamic, 4)
  for (int k = 0; k < count; ++k) {
    Cursor at;
    for (const Contact& c : slabs[k].pairs) check(c, at);
    for (const Contact& c : slabs[k].statics) check(c, at);
    for (const Contact& c : slabs[k].serial) check(c, at);
  }
}

// Wakes every sleeper at or above its region's level; returns how many.
std::size_t wake_above(World& world, const SleepRegions& regions, const Levels& levels) {
  SphereTable& spheres = world.spheres;
  auto x = spheres.position();
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  const std::int64_t first = static_cast<std::int64_t>(row_spans(asleep).asleep_begin);
  const std::int64_t n = static_cast<std::int64_t>(spheres.size());
  std::size_t woken = 0;
#pragma omp parallel for schedule(static) reduction(+ : woken)
  for (std::int64_t i = first; i < n; ++i)
    if (asleep[i] && regions.height(x[i]) >= levels[regions.of(x[i])]) {
      asleep[i] = 0;
      still[i] = 0.0f;
      ++woken;
    }
  return woken;
}

}  // namespace

Access WakeSystem::access() const {
  Access a;
  a.reads = {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereRadius,
             ColumnId::Colliders,      ColumnId::Gravity,        ColumnId::Grid};
  a.writes = {ColumnId::SphereSleep};
  return a;
}

Access SleepSystem::access() const {
  Access a;
  a.reads = {ColumnId::SpherePosition, ColumnId::SphereRadius, ColumnId::Colliders,
             ColumnId::Gravity,        ColumnId::Grid,         ColumnId::Contacts};
  a.writes = {ColumnId::SphereSleep, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity};
  return a;
}

std::size_t wake_approached(World& world) {
  const TeamSize team(team_for(world.spheres.size(), kRowsPerThread));
  if (!any_asleep(world.spheres.asleep())) return 0;
  const SleepRegions regions = regions_of(world);
  Levels levels(regions.size(), kNoLevel);
  mark_motion(world, regions, kApproachWakeFactor * world.solver.wake_speed, levels);
  if (!SleepRegions::any_level(levels)) return 0;
  return wake_above(world, regions, levels);
}

void update_sleep(World& world) {
  const TeamSize team(team_for(world.spheres.size(), kRowsPerThread));
  SphereTable& spheres = world.spheres;
  const SolverSettings& s = world.solver;
  if (all_asleep(spheres.asleep())) return;  // nothing moved, nothing was solved
  const SleepRegions regions = regions_of(world);
  auto x = spheres.position();
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  auto v = spheres.mut_velocity();
  auto r = spheres.radius();
  const bool angular = spheres.has_angular();
  auto w = angular ? spheres.mut_angular_velocity() : std::span<Vec3>{};
  const float dt = world.step();
  const float sleep2 = s.sleep_speed * s.sleep_speed;
  // The rows the grid sorted awake (systems/sleep_regions.h: RowSpans); the sleepers after them.
  const RowSpans spans = row_spans(spheres.asleep());
  std::int64_t n = static_cast<std::int64_t>(spans.awake_end);

  // The clock: the regions matter for falling asleep only once a sphere has been still for
  // sleep_time: slower than sleep_speed, and near where its still time began.
  auto from = spheres.mut_still_from();
  bool ready = false;
#pragma omp parallel for schedule(static) reduction(|| : ready)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i]) continue;
    const float spin = angular ? w[i].squaredNorm() * r[i] * r[i] : 0.0f;
    const float drift = kStillDriftFraction * r[i];
    if (v[i].squaredNorm() < sleep2 && spin < sleep2 && (x[i] - from[i]).squaredNorm() <= drift * drift) {
      still[i] += dt;
    } else {
      still[i] = 0.0f;
      from[i] = x[i];
    }
    ready = ready || still[i] >= s.sleep_time;
  }

  // Restless levels: in each region, the lowest awake sphere not yet still for sleep_time, and
  // the lowest point that motion may reach in the next step (which would only wake what sleeps
  // there again); the contacts below lower them under a deep contact. Rows come sorted by grid
  // cell, so runs of rows share a region: each thread lowers a region once per run. The regions
  // with an awake sphere under their level are the candidates: all that may sleep after this step.
  Levels restless;
  std::vector<std::uint8_t> candidates, near;
  bool any_candidate = false;
  if (ready) {
    restless.assign(regions.size(), kNoLevel);
    candidates.assign(regions.size(), 0);
    mark_motion(world, regions, s.wake_speed, restless);
#pragma omp parallel
    {
      std::uint32_t last = ~0u;
      float lowest = kNoLevel;
#pragma omp for schedule(static) nowait
      for (std::int64_t i = 0; i < n; ++i) {
        if (asleep[i] || still[i] >= s.sleep_time) continue;
        const std::uint32_t region = regions.of(x[i]);
        if (region != last) {
          if (last != ~0u) SleepRegions::lower(restless[last], lowest);
          last = region;
          lowest = kNoLevel;
        }
        lowest = std::min(lowest, regions.height(x[i]));
      }
      if (last != ~0u) SleepRegions::lower(restless[last], lowest);
#pragma omp barrier
#pragma omp for schedule(static) reduction(|| : any_candidate)
      for (std::int64_t i = 0; i < n; ++i) {
        if (asleep[i]) continue;
        const std::uint32_t region = regions.of(x[i]);
        if (!regions.sleeps_under(restless[region], regions.height(x[i]))) continue;
        set_mark(candidates[region]);
        any_candidate = true;
      }
    }
    if (any_candidate) regions.dilate(candidates, 2, near);
  }

  // A sleeper the solver struck hard (kStruckWakeFactor), or that an awake sphere presses deeper
  // than the bound, wakes with the sleepers of its region from a region's width under it up: the
  // step treated it as fixed, the next one moves it. Their clocks start again, so that part of
  // the region is restless too.
  Levels struck(regions.size(), kNoLevel);
  const bool sleepers = any_asleep(spheres.asleep());
  const std::vector<std::uint8_t>& requests = world.contacts.wake_requests;
  if (sleepers && requests.size() == spheres.size())
    for (std::size_t i = spans.asleep_begin; i < requests.size(); ++i)
      if (requests[i]) SleepRegions::lower(struck[regions.of(x[i])], regions.wake_level_under(x[i]));
  if (sleepers || any_candidate)
    mark_contacts(world, regions, sleepers, struck, any_candidate ? &near : nullptr, any_candidate ? &restless : nullptr);
  // Spheres it wakes are awake rows among the sleepers': the pass below takes every row then.
  if (SleepRegions::any_level(struck) && wake_above(world, regions, struck) > 0) {
    n = static_cast<std::int64_t>(spheres.size());
    if (any_candidate)
      for (std::size_t k = 0; k < struck.size(); ++k) restless[k] = std::min(restless[k], struck[k]);
  }
  if (!any_candidate) return;  // every awake sphere's region is restless

#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i)
    if (!asleep[i] && regions.sleeps_under(restless[regions.of(x[i])], regions.height(x[i]))) {
      asleep[i] = 1;
      v[i].setZero();
      if (angular) w[i].setZero();
    }
}

}  // namespace ballpit
