// The headless runner: builds a scene, steps it with per-system timing, and reports the
// figures shared/SCENES.md defines as one JSON line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ballpit {

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
  // Snapshots (engine/snapshot.h): load_path replaces building the scene (then only flags that
  // were given override the snapshot's settings); save_path is written after the run, and
  // also, with the last good state, when the NaN guard stops a run.
  std::string load_path;
  std::string save_path;
  // "key.path=value" overrides of the scene file (scene ending in .json) or the embedded default
  // pour; the scene's spheres and steps then replace the two fields above.
  std::vector<std::string> set;
};

// Runs the scene and returns the report (also what the CLI prints). Throws ballpit::Error for
// bad options, naming the flag.
nlohmann::ordered_json run_headless(const RunOptions& options);

class World;
// The report line of a run that took step_ms (unit: ms) per step and ended in `world`; the
// app's offscreen run reports the same fields.
nlohmann::ordered_json step_report(const std::string& scene, const World& world, int threads,
                                   const std::vector<double>& step_ms);

}  // namespace ballpit
