#include "app/headless_run.h"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <vector>

#include "app/step_warnings.h"
#include "engine/atomic_file.h"
#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/memory_budget.h"
#include "engine/memory_use.h"
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
#include "systems/scene_setup.h"
#include "systems/substep_control.h"

namespace ballpit {

namespace {

// Where a run stopped by the NaN guard saves its last good state when --save was not given.
constexpr const char* kLastGoodSnapshot = "ballpit-last-good.snap";

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

// What each table and system holds at the end of the run, in bytes a sphere (engine/memory_use.h),
// printed as a table beside the systems' times when asked. Peak RSS also counts the program,
// its libraries, and what was freed before the end.
nlohmann::ordered_json memory_breakdown(const World& world, const Scheduler& scheduler, bool print) {
  nlohmann::ordered_json j;
  const double n = static_cast<double>(std::max<std::size_t>(world.spheres.size(), 1));
  double total = 0.0;
  std::string table = "memory held                            bytes/sphere\n";
  auto add_line = [&](const std::string& name, double per) {
    char line[96];
    std::snprintf(line, sizeof line, "%-38s %12.1f\n", name.c_str(), per);
    table += line;
  };
  for (const MemoryItem& item : memory_by_table(world, scheduler)) {
    const double per = static_cast<double>(item.bytes) / n;
    total += per;
    j[item.table] = round_to(per, 1);
    add_line(item.table, per);
  }
  add_line("(all tables)", total);
  if (print) std::fprintf(stderr, "%s", table.c_str());
  j["all tables"] = round_to(total, 1);
  return j;
}

}  // namespace

nlohmann::ordered_json run_headless(const RunOptions& options) {
  RunOptions o = options;  // a scene file sets spheres and steps
  // A scene file (engine/scene_file.h), or a built-in scene's embedded file when --set is given.
  const bool use_file = o.scene.ends_with(".json") || (is_builtin_scene(o.scene) && !o.set.empty());
  const bool builtin_character = o.scene == "pit-character" && !use_file;
  SceneFile file_scene;
  if (use_file) {
    file_scene = load_scene(o.scene, o.set);
    o.spheres = file_scene.total_spheres();
    o.steps = file_scene.steps;
  }
  if (!is_builtin_scene(o.scene) && !use_file)
    throw Error("--scene: unknown scene '" + o.scene + "' (known: pour, pit-character, or a .json scene file)");
  if (!o.set.empty() && !use_file) throw Error("--set: works with --scene pour, pit-character or a .json scene file");
  if (o.spheres < 1) throw Error("--spheres must be >= 1");
  if (o.steps < 1) throw Error("--steps must be >= 1");
  refuse_if_too_big(o.spheres);
  if (o.threads < 1) throw Error("--threads must be >= 1");
  if (o.tolerance_r != 0.0 && !(o.tolerance_r > 0.0 && o.tolerance_r <= 1.0))
    throw Error("--tolerance must be in (0, 1] (largest overlap after a step, as a fraction of the ball radius)");
  check_output_path("--trace", o.trace_path);
  check_output_path("--save", o.save_path);
  omp_set_num_threads(o.threads);

  World world;
  PourScene scene;
  scene.spheres = o.spheres;
  PitCharacterScene pit_character;
  pit_character.pour = scene;
  Entity walker;
  SceneSetup file_setup;
  const bool loaded = !o.load_path.empty();
  if (loaded && (builtin_character || use_file)) throw Error("--load: the snapshot is the scene; leave out --scene and --set");
  double load_ms = 0.0;
  if (loaded) {
    auto l0 = std::chrono::steady_clock::now();
    load_snapshot(world, o.load_path);
    load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - l0).count();
  } else if (builtin_character) {
    walker = pit_character.build(world);
  } else if (use_file) {
    file_setup = setup_scene(file_scene, world);
  } else {
    scene.build(world);
  }
  // A snapshot or scene file carries its own solver settings: only flags given override them.
  if (!(loaded || use_file) || o.sleeping) world.solver.sleeping = o.sleeping;
  if (o.naive) world.solver.narrowphase = NarrowphaseMode::Naive;
  if (o.substeps > 0) world.set_substeps(o.substeps);
  if (o.solve_sweeps > 0) world.set_solve_sweeps(o.solve_sweeps);
  world.validate_settings();
  print_step_warnings(world, o.tolerance_r > 0.0);

  Scheduler scheduler(o.threads);
  scheduler.profiler().set_tracing(!o.trace_path.empty());
  add_character_systems(scheduler, world);  // none without a character
  add_physics_systems(scheduler, world);
  // --tolerance: after each step, substeps for the next one from the overlap this one left.
  SubstepControlSystem* substep_control = nullptr;
  if (o.tolerance_r > 0.0) {
    SubstepControlSettings control;
    control.tolerance_r = o.tolerance_r;
    substep_control = &scheduler.emplace<SubstepControlSystem>(control);
  }
  FixedStepLoop loop(world, scheduler);
  // With a character (built in, from a scene file, or in a loaded snapshot) the report adds
  // the character's figures. A freshly built one first stands while the pour settles around
  // it, untimed; --steps then counts its path (600 = the canonical 10 s) and the profiler
  // shows only those. A loaded snapshot resumes where it was saved.
  const bool character = world.characters.size() > 0;
  ColliderOverlap worst_overlap;
  double fastest_ball = 0.0;
  if (character && !loaded) {
    const int settle_steps = builtin_character ? pit_character.settle_steps : file_setup.settle_steps;
    if (o.progress) std::fprintf(stderr, "[ballpit] settling %d steps before the path\n", settle_steps);
    if (builtin_character) {
      pit_character.settle(world, scheduler);
      pit_character.start_path(world, walker);
    } else {
      settle_scene(file_setup, world, scheduler);
      start_scene_path(file_setup, world);
    }
    scheduler.profiler().reset();
    if (substep_control) substep_control->reset_stats();  // the report covers the path only
  }
  // The NaN guard keeps the last good state (a snapshot: spheres and characters), from here on.
  std::optional<NanGuard> guard;
  guard.emplace(world);

  std::vector<double> step_ms;
  step_ms.reserve(static_cast<std::size_t>(o.steps));
  double awake_sum = 0.0;  // spheres awake after each step, summed (outside the timing)
  long long pass_sum = 0;  // passes each step took (engine/step_passes.h), summed
  int pass_max = 0;
  auto started = std::chrono::steady_clock::now();
  auto last_report = started;
  double guard_ms = 0.0;  // the guard's checks and checkpoints, outside the step's timing
  // Nothing but the loop writes the world between the guard's checks (after_step takes a const
  // World), so its check after each step stands for the one before the next (NanGuard::step).
  if (guard) guard->before_step(world);
  for (int s = 0; s < o.steps; ++s) {
    auto t0 = std::chrono::steady_clock::now();
    loop.step();
    auto t1 = std::chrono::steady_clock::now();
    step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    pass_sum += world.passes.passes;
    pass_max = std::max(pass_max, world.passes.passes);
    if (o.after_step) o.after_step(world);
    if (world.solver.sleeping) {
      auto asleep = world.spheres.asleep();
      awake_sum += static_cast<double>(std::count(asleep.begin(), asleep.end(), std::uint8_t{0}));
    }
    if (guard) {
      const auto g0 = std::chrono::steady_clock::now();
      try {
        guard->after_step(world, scheduler);
        guard_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - g0).count();
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
  report["bytes_per_sphere_by_table"] = memory_breakdown(world, scheduler, o.print_table);
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
  // Passes the steps were split into, for motion too fast for a capped margin (engine/step_passes.h),
  // and the steps that needed more than a step may take (warned of once, as they happen).
  report["nan_guard_ms_per_step"] = round_to(step_ms.empty() ? 0.0 : guard_ms / static_cast<double>(step_ms.size()), 3);
  report["passes_max"] = pass_max;
  report["passes_mean"] = round_to(step_ms.empty() ? 0.0 : static_cast<double>(pass_sum) / static_cast<double>(step_ms.size()), 3);
  report["steps_short_of_passes"] = world.passes.steps_short;
  if (world.solver.sleeping) {  // how much of the pit the steps moved (systems/sleeping.h)
    report["awake_mean"] = round_to(step_ms.empty() ? 0.0 : awake_sum / static_cast<double>(step_ms.size()), 1);
    auto asleep = world.spheres.asleep();
    report["awake_final"] = std::count(asleep.begin(), asleep.end(), std::uint8_t{0});
  }
  if (substep_control) {
    // What the tolerance achieved (worst overlap the controller measured after a step) and what
    // it cost (substeps used per step); the timing above includes the controller itself.
    const SubstepControlStats& st = substep_control->stats();
    report["tolerance_r"] = o.tolerance_r;
    report["max_step_penetration_r"] = round_to(st.max_overlap_r, 6);
    report["steps_over_tolerance"] = st.steps_over;
    report["substeps_mean"] = round_to(st.substeps_mean(), 3);
    report["substeps_min"] = st.substeps_min;
    report["substeps_max"] = st.substeps_max;
    report["substeps_final"] = world.solver.substeps;
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

void check_output_path(std::string_view flag, const std::string& path) {
  if (path.empty()) return;
  try {
    check_writable(path);
  } catch (const Error& e) {
    throw Error(std::string(flag) + ": " + e.what() + "; nothing was run");
  }
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
  j["pit_half_width_m"] = world.pit.half_width;  // the pit-character scene may widen it
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
