#include "systems/nan_guard.h"

#include <algorithm>
#include <cstdint>
#include <limits>

#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "engine/thread_share.h"
#include "engine/world.h"

namespace ballpit {

namespace {

// Rows worth a thread of their own: the check only streams 36 bytes a row, so a second thread
// pays for its wake-up only on big worlds.
constexpr std::size_t kRowsPerThread = 65536;

}  // namespace

std::optional<NonFiniteValue> find_non_finite(const World& world) {
  const SphereTable& t = world.spheres;
  auto x = t.position();
  auto v = t.velocity();
  std::span<const Vec3> w;
  if (t.has_angular()) w = t.angular_velocity();
  const std::int64_t n = static_cast<std::int64_t>(t.size());
  // A team only for big worlds: at 1k spheres this check, twice a step, was the one loop that
  // woke a second thread, which then spun beside the step's single-threaded systems (47% of the
  // run's samples on that thread).
  const TeamSize team(team_for(t.size(), kRowsPerThread));
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
#pragma omp parallel for schedule(static) reduction(min : first)
  for (std::int64_t i = 0; i < n; ++i) {
    bool ok = x[i].allFinite() && v[i].allFinite() && (w.empty() || w[i].allFinite());
    if (!ok) first = std::min(first, i);
  }
  if (first == std::numeric_limits<std::int64_t>::max()) return std::nullopt;
  const auto row = static_cast<std::uint32_t>(first);
  const char* field = !x[row].allFinite() ? "position" : !v[row].allFinite() ? "velocity" : "angular_velocity";
  return NonFiniteValue{t.entity_at(row), field};
}

NanGuard::NanGuard(const World& world) {
  if (auto bad = find_non_finite(world))
    throw Error("nan guard: " + to_string(bad->entity) + " already has a non-finite " + bad->field);
  capture_snapshot(world, last_good_);
}

void NanGuard::step(FixedStepLoop& loop, World& world, Scheduler& scheduler) {
  before_step(world);
  loop.step();
  after_step(world, scheduler);
}

void NanGuard::before_step(const World& world) const {
  // A value poked in between steps (by the app or a test) is named before it can spread.
  if (const auto bad = find_non_finite(world)) {
    throw NonFiniteState("non-finite " + bad->field + " in " + to_string(bad->entity) + " before step " +
                         std::to_string(world.step_count) + ", set outside the scheduled systems");
  }
}

void NanGuard::after_step(const World& world, Scheduler& scheduler) {
  const auto bad = find_non_finite(world);
  if (!bad) {
    capture_snapshot(world, last_good_);
    return;
  }
  throw NonFiniteState("non-finite " + bad->field + " in " + to_string(bad->entity) + " during step " +
                       std::to_string(world.step_count - 1) + ", " + locate(scheduler, *bad));
}

std::string NanGuard::locate(Scheduler& scheduler, const NonFiniteValue& bad) const {
  // Replay the step on a copy, in registration order (a valid order: dependencies only run
  // from earlier-added systems to later ones), checking after each system.
  World replay;
  restore_snapshot(last_good_, replay, "nan guard replay");
  if (find_non_finite(replay)) return "already present before the step";
  for (std::size_t i = 0; i < scheduler.size(); ++i) {
    System& system = scheduler.system(i);
    system.run(replay);
    if (auto found = find_non_finite(replay)) {
      std::string where = "first after system '" + std::string(system.name()) + "'";
      if (found->entity != bad.entity) where += " (replayed: first in " + to_string(found->entity) + ")";
      return where;
    }
  }
  return "not reproduced by replaying the step's systems";
}

}  // namespace ballpit
