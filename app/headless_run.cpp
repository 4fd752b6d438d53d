#include "app/headless_run.h"

#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <cstdio>
#include <vector>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/metrics.h"
#include "engine/pour_scene.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/snapshot.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/joint_colliders.h"
#include "systems/nan_guard.h"
#include "systems/physics_pipeline.h"
#include "systems/pit_character_scene.h"

namespace ballpit {

namespace {

// Where a run stopped by the NaN guard saves its last good state when --save was not given.
constexpr const char* kLastGoodSnapshot = "ballpit-last-good.snap";

// Peak memory a sphere costs in a pour run, all of it: columns, grid, contacts, warm-start
// cache, the NaN guard's last good copy and the allocator's slack (unit: bytes). Measured as
// peak RSS / N of a settled 100k pour (850 B, this session), rounded up for headroom.
constexpr double kPeakBytesPerSphere = 1000.0;

// Refuses a run whose estimated peak memory exceeds the machine's physical memory, before
// allocating anything, with the estimate in the message.
void refuse_if_too_big(std::size_t spheres) {
  const double physical = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  const double need = static_cast<double>(spheres) * kPeakBytesPerSphere;
  if (physical > 0 && need > physical) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "--spheres %zu needs about %.1f GiB (%.0f bytes a sphere), more than this machine's %.1f GiB; "
                  "expected at most %.0f spheres",
                  spheres, need / 1073741824.0, kPeakBytesPerSphere, physical / 1073741824.0, physical / kPeakBytesPerSphere);
    throw Error(text);
  }
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

struct PhaseTimes {
  double mean = 0, median = 0;
};

PhaseTimes summarize(std::vector<double> ms) {
  PhaseTimes t;
  if (ms.empty()) return t;
  double sum = 0;
  for (double x : ms) sum += x;
  t.mean = sum / static_cast<double>(ms.size());
  std::sort(ms.begin(), ms.end());
  t.median = ms[ms.size() / 2];
  return t;
}

double round_to(double x, double digits) {
  double f = std::pow(10.0, digits);
  return std::round(x * f) / f;
}

}  // namespace

nlohmann::ordered_json run_headless(const RunOptions& options) {
  RunOptions o = options;  // a scene file sets spheres and steps
  const bool character = o.scene == "pit-character";
  // A scene file (engine/scene_file.h), or the embedded default pour when only --set is given.
  const bool use_file = o.scene.ends_with(".json") || (o.scene == "pour" && !o.set.empty());
  SceneFile file_scene;
  if (use_file) {
    file_scene = load_scene(o.scene.ends_with(".json") ? o.scene : std::string(), o.set);
    o.spheres = file_scene.pour.spheres;
    o.steps = file_scene.pour.steps;
  }
  if (o.scene != "pour" && !character && !use_file)
    throw Error("--scene: unknown scene '" + o.scene + "' (known: pour, pit-character, or a .json scene file)");
  if (!o.set.empty() && !use_file) throw Error("--set: works with --scene pour or a .json scene file");
  if (o.spheres < 1) throw Error("--spheres must be >= 1");
  if (o.steps < 1) throw Error("--steps must be >= 1");
  refuse_if_too_big(o.spheres);
  if (o.threads < 1) throw Error("--threads must be >= 1");
  omp_set_num_threads(o.threads);

  World world;
  PourScene scene;
  scene.spheres = o.spheres;
  PitCharacterScene pit_character;
  pit_character.pour = scene;
  Entity walker;
  const bool loaded = !o.load_path.empty();
  if (loaded && (character || use_file)) throw Error("--load: the snapshot is the scene; leave out --scene and --set");
  double load_ms = 0.0;
  if (loaded) {
    auto l0 = std::chrono::steady_clock::now();
    load_snapshot(world, o.load_path);
    load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - l0).count();
  } else if (character) {
    walker = pit_character.build(world);
  } else if (use_file) {
    build_scene(file_scene, world);
  } else {
    scene.build(world);
  }
  // A snapshot or scene file carries its own solver settings: only flags given override them.
  if (!(loaded || use_file) || o.sleeping) world.solver.sleeping = o.sleeping;
  if (o.naive) world.solver.narrowphase = NarrowphaseMode::Naive;
  if (o.substeps > 0) world.solver.substeps = o.substeps;
  world.validate_settings();

  Scheduler scheduler(o.threads);
  scheduler.profiler().set_tracing(!o.trace_path.empty());
  add_character_systems(scheduler, world);  // none without a character
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);
  if (!o.save_path.empty()) check_snapshot_supported(world);  // refuse before the run, not after
  // The NaN guard keeps the last good state; snapshots (and so the guard) skip characters.
  std::optional<NanGuard> guard;
  if (!character) guard.emplace(world);
  // pit-character: the pour settles around the standing character first, untimed; --steps
  // then counts the scripted path (600 = its 10 s) and the profiler shows only those.
  ColliderOverlap worst_overlap;
  double fastest_ball = 0.0;
  if (character) {
    if (o.progress) std::fprintf(stderr, "[ballpit] settling %d steps before the path\n", pit_character.settle_steps);
    pit_character.settle(world, scheduler);
    pit_character.start_path(world, walker);
    scheduler.profiler().reset();
  }

  std::vector<double> step_ms;
  step_ms.reserve(static_cast<std::size_t>(o.steps));
  auto started = std::chrono::steady_clock::now();
  auto last_report = started;
  for (int s = 0; s < o.steps; ++s) {
    if (guard) guard->before_step(world);  // the guard's checks stay outside the timing
    auto t0 = std::chrono::steady_clock::now();
    loop.step();
    auto t1 = std::chrono::steady_clock::now();
    step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    if (guard) {
      try {
        guard->after_step(world, scheduler);
      } catch (const NonFiniteState& e) {
        const std::string path = o.save_path.empty() ? std::string(kLastGoodSnapshot) : o.save_path;
        save_snapshot(guard->last_good(), path);
        throw Error(std::string(e.what()) + "; the last good state (step " +
                    std::to_string(guard->last_good().step_count) + ") is saved in '" + path + "'");
      }
    }
    if (character) {  // after each step, outside the timing
      const ColliderOverlap overlap = measure_collider_overlap(world);
      worst_overlap.max_depth_r = std::max(worst_overlap.max_depth_r, overlap.max_depth_r);
      worst_overlap.inside = std::max(worst_overlap.inside, overlap.inside);
      for (const Vec3& v : world.spheres.velocity()) fastest_ball = std::max(fastest_ball, static_cast<double>(v.norm()));
    }
    if (o.progress && t1 - last_report > std::chrono::seconds(5)) {
      last_report = t1;
      double elapsed = std::chrono::duration<double>(t1 - started).count();
      std::fprintf(stderr, "[ballpit] step %d/%d, %.1f s elapsed, about %.0f s left\n", s + 1, o.steps,
                   elapsed, elapsed / (s + 1) * (o.steps - s - 1));
    }
  }

  if (o.print_table) std::fprintf(stderr, "%s", scheduler.profiler().table().c_str());
  if (!o.trace_path.empty()) scheduler.profiler().write_trace(o.trace_path);

  nlohmann::ordered_json report = step_report(o.scene, world, o.threads, step_ms);
  if (loaded) {
    report["loaded"] = o.load_path;
    report["load_ms"] = round_to(load_ms, 1);
  }
  if (!o.save_path.empty()) {
    auto s0 = std::chrono::steady_clock::now();
    save_snapshot(world, o.save_path);
    report["saved"] = o.save_path;
    report["save_ms"] = round_to(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count(), 1);
  }
  if (character) {
    // Worst step of the run: deepest ball in a collider, and most balls deeper than 1% r.
    report["max_collider_penetration_r"] = round_to(worst_overlap.max_depth_r, 6);
    report["balls_inside_colliders"] = worst_overlap.inside;
    double character_ms = 0.0;
    for (const SystemStats& s : scheduler.profiler().stats())
      for (std::string_view name : character_system_names())
        if (s.name == name) character_ms += s.mean_ms;
    report["character_ms_per_step"] = round_to(character_ms, 4);
    report["max_speed_during_run_mps"] = round_to(fastest_ball, 6);  // SCENES.md: "the highest ball speed"
  }
  return report;
}

nlohmann::ordered_json step_report(const std::string& scene, const World& world, int threads,
                                   const std::vector<double>& step_ms) {
  const int steps = static_cast<int>(step_ms.size());
  // SCENES.md: steps 0-299 are "pour", 300-599 "settled"; other lengths split in halves.
  std::size_t split = steps == 600 ? 300 : static_cast<std::size_t>(steps) / 2;
  PhaseTimes pour = summarize({step_ms.begin(), step_ms.begin() + static_cast<std::ptrdiff_t>(split)});
  PhaseTimes settled = summarize({step_ms.begin() + static_cast<std::ptrdiff_t>(split), step_ms.end()});
  Metrics m = measure(world);
  double rss = peak_rss_mb();

  nlohmann::ordered_json j;
  j["scene"] = scene;
  j["spheres"] = world.spheres.size();
  j["threads"] = threads;
  j["steps"] = steps;
  j["dt"] = world.step();
  j["ms_per_step_pour_mean"] = round_to(pour.mean, 4);
  j["ms_per_step_pour_median"] = round_to(pour.median, 4);
  j["ms_per_step_settled_mean"] = round_to(settled.mean, 4);
  j["ms_per_step_settled_median"] = round_to(settled.median, 4);
  j["max_penetration_r"] = round_to(m.max_penetration_r, 6);
  j["mean_penetration_r"] = round_to(m.mean_penetration_r, 6);
  j["max_wall_penetration_r"] = round_to(m.max_wall_penetration_r, 6);
  j["escaped"] = m.escaped;
  j["kinetic_energy_j"] = round_to(m.kinetic_energy_j, 8);
  j["max_speed_mps"] = round_to(m.max_speed_mps, 6);
  j["peak_rss_mb"] = round_to(rss, 1);
  j["bytes_per_sphere"] = round_to(rss * 1048576.0 / static_cast<double>(world.spheres.size()), 1);
  j["state_hash"] = hash_hex(state_hash(world));
  return j;
}

}  // namespace ballpit
