// The headless runner: builds a scene, steps it with per-system timing, and reports the
// figures shared/SCENES.md defines as one JSON line.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace ballpit {

class World;

struct RunOptions {
  std::string scene = "pour";
  std::size_t spheres = 100000;
  int steps = 600;
  int threads = 2;
  std::string trace_path;     // Chrome trace JSON, empty for none
  bool progress = true;       // progress lines on stderr for long runs
  bool print_table = true;    // per-system table on stderr
  bool sleeping = false;      // the canonical pour measures with sleeping off
  bool naive = false;         // reference all-pairs narrowphase
  int substeps = 0;           // 0 keeps the scene's value
  int solve_sweeps = 0;       // 0 keeps the scene's value
  // --tolerance: largest overlap allowed after a step, as a fraction of the ball radius; the
  // substeps then change every step to keep it (systems/substep_control.h), starting from the
  // scene's (or --substeps). 0: fixed substeps.
  double tolerance_r = 0.0;
  // Snapshots (engine/snapshot.h): load_path replaces building the scene (then only flags that
  // were given override the snapshot's settings); save_path is written after the run, and
  // also, with the last good state, when the NaN guard stops a run.
  std::string load_path;
  std::string save_path;
  // "key.path=value" overrides of the scene file (scene ending in .json) or of a built-in scene's
  // embedded file (pour, pit-character); the scene's spheres (all populations) and steps then
  // replace the two fields above.
  std::vector<std::string> set;
  // Called after every timed step, outside the timing (the Bullet comparison follows the
  // kinetic energy with it). Empty: nothing.
  std::function<void(const World&)> after_step;
};

// Runs the scene and returns the report (also what the CLI prints). Throws ballpit::Error for
// bad options, naming the flag.
nlohmann::ordered_json run_headless(const RunOptions& options);

// Throws ballpit::Error naming `flag` if a write of `path` at the run's end would fail
// (check_writable, engine/atomic_file.h), so that it fails before the run instead; an empty
// path is no output and passes.
void check_output_path(std::string_view flag, const std::string& path);

// The report line of a run that took step_ms (unit: ms) per step and ended in `world`; the
// app's offscreen run reports the same fields.
nlohmann::ordered_json step_report(const std::string& scene, const World& world, int threads,
                                   const std::vector<double>& step_ms);

}  // namespace ballpit
