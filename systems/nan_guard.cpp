#include "systems/nan_guard.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "engine/state_hash.h"
#include "engine/thread_share.h"
#include "engine/world.h"

namespace ballpit {

namespace {

// Rows worth a thread of their own: the check only streams 36 bytes a row, so a second thread
// pays for its wake-up only on big worlds.
constexpr std::size_t kRowsPerThread = 65536;
// Rows checked together: a block is scanned as flat floats, and only a block with a bad value is
// searched row by row.
constexpr std::size_t kBlockRows = 4096;

// Whether rows [begin, end) of a column of vectors are all finite. |f| <= FLT_MAX is false for
// NaN and the infinities, and the loop over flat floats vectorizes, where allFinite() row by row
// did not (the check of a settled 1M pit took 6 ms; a Vec3 is three packed floats).
bool finite_rows(std::span<const Vec3> column, std::size_t begin, std::size_t end) {
  if (column.empty()) return true;
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  const float* f = column.data()->data() + 3 * begin;
  const std::size_t count = 3 * (end - begin);
  int ok = 1;
  for (std::size_t i = 0; i < count; ++i) ok &= std::fabs(f[i]) <= std::numeric_limits<float>::max();
  return ok != 0;
}

}  // namespace

std::optional<NonFiniteValue> find_non_finite(const World& world) {
  const SphereTable& t = world.spheres;
  auto x = t.position();
  auto v = t.velocity();
  std::span<const Vec3> w;
  if (t.has_angular()) w = t.angular_velocity();
  const std::size_t n = t.size();
  // A team only for big worlds: at 1k spheres this check, twice a step, was the one loop that
  // woke a second thread, which then spun beside the step's single-threaded systems (47% of the
  // run's samples on that thread).
  const TeamSize team(team_for(n, kRowsPerThread));
  const std::int64_t blocks = static_cast<std::int64_t>((n + kBlockRows - 1) / kBlockRows);
  std::int64_t first_bad = std::numeric_limits<std::int64_t>::max();
#pragma omp parallel for schedule(static) reduction(min : first_bad)
  for (std::int64_t b = 0; b < blocks; ++b) {
    const std::size_t begin = static_cast<std::size_t>(b) * kBlockRows, end = std::min(n, begin + kBlockRows);
    if (!(finite_rows(x, begin, end) && finite_rows(v, begin, end) && finite_rows(w, begin, end)))
      first_bad = std::min(first_bad, b);
  }
  if (first_bad == std::numeric_limits<std::int64_t>::max()) return std::nullopt;
  auto finite = [&](std::size_t i) { return x[i].allFinite() && v[i].allFinite() && (w.empty() || w[i].allFinite()); };
  std::size_t row = static_cast<std::size_t>(first_bad) * kBlockRows;  // the lowest bad row is in this block
  while (finite(row)) ++row;
  const char* field = !x[row].allFinite() ? "position" : !v[row].allFinite() ? "velocity" : "angular_velocity";
  return NonFiniteValue{t.entity_at(static_cast<std::uint32_t>(row)), field};
}

NanGuard::NanGuard(const World& world) {
  if (auto bad = find_non_finite(world))
    throw Error("nan guard: " + to_string(bad->entity) + " already has a non-finite " + bad->field);
  capture_snapshot(world, checkpoint_);
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
    if (++steps_since_checkpoint_ >= kCheckpointSteps) {
      capture_snapshot(world, checkpoint_);
      steps_since_checkpoint_ = 0;
    }
    return;
  }
  const std::string replayed = replay_to_last_good(world, scheduler);
  throw NonFiniteState("non-finite " + bad->field + " in " + to_string(bad->entity) + " during step " +
                       std::to_string(world.step_count - 1) + ", " + locate(scheduler, *bad) + replayed);
}

std::string NanGuard::replay_to_last_good(const World& world, Scheduler& scheduler) {
  // The good steps since the checkpoint, then the bad one to check that the replay came back to
  // the world's state to the bit: it does when only the loop changed the world between steps.
  failed_ = true;
  try {
    World replay;
    restore_snapshot(checkpoint_, replay, "nan guard replay");
    FixedStepLoop loop(replay, scheduler);
    loop.warn = [](const std::string&) {};  // the run warned already
    for (int k = 0; k < steps_since_checkpoint_ && !find_non_finite(replay); ++k) loop.step();
    if (!find_non_finite(replay)) {
      capture_snapshot(replay, last_good_);
      loop.step();
      if (state_hash(replay) == state_hash(world)) return "";
    }
  } catch (const Error&) {
    // as below: the replay did not come back to the bad step
  }
  last_good_ = checkpoint_;
  return "; replaying from the last checkpoint (step " + std::to_string(checkpoint_.step_count) +
         ") did not come back to it (was the world changed between steps?), so the last good state is that checkpoint's";
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
