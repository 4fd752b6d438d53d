// The headless runner: builds a scene, steps it with per-system timing, and reports the
// figures shared/SCENES.md defines as one JSON line.
#pragma once

#include <cstdint>
#include <string>

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
};

// Runs the scene and returns the report (also what the CLI prints). Throws ballpit::Error for
// bad options, naming the flag.
nlohmann::ordered_json run_headless(const RunOptions& options);

}  // namespace ballpit
