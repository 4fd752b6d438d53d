#include "app/headless_run.h"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/metrics.h"
#include "engine/pour_scene.h"
#include "engine/scheduler.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "systems/physics_pipeline.h"

namespace ballpit {

namespace {

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

nlohmann::ordered_json run_headless(const RunOptions& o) {
  if (o.scene != "pour") throw Error("--scene: unknown scene '" + o.scene + "' (known: pour)");
  if (o.spheres < 1) throw Error("--spheres must be >= 1");
  if (o.steps < 1) throw Error("--steps must be >= 1");
  if (o.threads < 1) throw Error("--threads must be >= 1");
  omp_set_num_threads(o.threads);

  World world;
  PourScene scene;
  scene.spheres = o.spheres;
  scene.build(world);
  world.solver.sleeping = o.sleeping;
  if (o.naive) world.solver.narrowphase = NarrowphaseMode::Naive;
  if (o.substeps > 0) world.solver.substeps = o.substeps;
  world.validate_settings();

  Scheduler scheduler(o.threads);
  scheduler.profiler().set_tracing(!o.trace_path.empty());
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);

  std::vector<double> step_ms;
  step_ms.reserve(static_cast<std::size_t>(o.steps));
  auto started = std::chrono::steady_clock::now();
  auto last_report = started;
  for (int s = 0; s < o.steps; ++s) {
    auto t0 = std::chrono::steady_clock::now();
    loop.step();
    auto t1 = std::chrono::steady_clock::now();
    step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    if (o.progress && t1 - last_report > std::chrono::seconds(5)) {
      last_report = t1;
      double elapsed = std::chrono::duration<double>(t1 - started).count();
      std::fprintf(stderr, "[ballpit] step %d/%d, %.1f s elapsed, about %.0f s left\n", s + 1, o.steps,
                   elapsed, elapsed / (s + 1) * (o.steps - s - 1));
    }
  }

  if (o.print_table) std::fprintf(stderr, "%s", scheduler.profiler().table().c_str());
  if (!o.trace_path.empty()) scheduler.profiler().write_trace(o.trace_path);

  // SCENES.md: steps 0-299 are "pour", 300-599 "settled"; other lengths split in halves.
  std::size_t split = o.steps == 600 ? 300 : static_cast<std::size_t>(o.steps) / 2;
  PhaseTimes pour = summarize({step_ms.begin(), step_ms.begin() + static_cast<std::ptrdiff_t>(split)});
  PhaseTimes settled = summarize({step_ms.begin() + static_cast<std::ptrdiff_t>(split), step_ms.end()});
  Metrics m = measure(world);
  double rss = peak_rss_mb();

  nlohmann::ordered_json j;
  j["scene"] = o.scene;
  j["spheres"] = world.spheres.size();
  j["threads"] = o.threads;
  j["steps"] = o.steps;
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
