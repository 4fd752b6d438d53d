// ballpit: the command line. `ballpit run ...` is the headless runner; see --help.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "app/headless_run.h"
#include "engine/error.h"

int main(int argc, char** argv) {
  CLI::App app{"ballpit: a multithreaded ball-pit physics engine"};
  app.require_subcommand(0, 1);

  ballpit::RunOptions run;
  CLI::App* cmd = app.add_subcommand("run", "Run a scene headless and print its report");
  cmd->add_option("--scene", run.scene, "Scene to run (pour)")->capture_default_str();
  cmd->add_option("--spheres", run.spheres, "Number of spheres N")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--steps", run.steps, "Fixed steps to run (1/60 s each)")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--threads", run.threads, "Worker threads (OpenMP and scheduler)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  cmd->add_option("--trace", run.trace_path, "Write a Chrome trace (JSON, opens in Perfetto) to this file");
  cmd->add_option("--substeps", run.substeps, "Solver substeps per step (default: the scene's)")->check(CLI::Range(1, 64));
  cmd->add_flag("--sleeping", run.sleeping, "Let settled spheres sleep (the canonical pour measures without)");
  cmd->add_flag("--naive", run.naive, "Reference all-pairs narrowphase instead of the grid (O(N^2))");
  cmd->add_flag("!--no-progress", run.progress, "Do not print progress lines on stderr");
  cmd->add_flag("!--no-table", run.print_table, "Do not print the per-system table on stderr");

  CLI11_PARSE(app, argc, argv);

  try {
    if (app.got_subcommand(cmd) || app.get_subcommands().empty()) {
      nlohmann::ordered_json report = ballpit::run_headless(run);
      std::cout << report.dump() << std::endl;
    }
  } catch (const ballpit::Error& e) {
    std::fprintf(stderr, "ballpit: %s\n", e.what());
    return 2;
  }
  return 0;
}
