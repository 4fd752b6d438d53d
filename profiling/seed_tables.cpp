// The original report's rows (shared/SCENES.md "seed tables"), as simulation cost per step: the
// pour scene at n = 50..400 and then 1k..1M spheres, with our grid, our naive all-pairs
// narrowphase (the original's k = 1) and no collisions at all (integration only). One JSON
// line per row on stdout; scripts/profile_seed_tables.sh makes the markdown from them.
//
// Each row also gives the grid our engine chose (cells along x, z and y, and the cell size):
// the original's grid had a fixed k cells per side, ours sizes cells from the largest sphere.
// A size that would not fit in memory (engine/memory_budget.h) is not run: its line says
// "refused" and why, and the report lists it.
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/memory_budget.h"
#include "engine/pour_scene.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/physics_pipeline.h"

namespace {

using namespace ballpit;

enum class Mode { Grid, Naive, NoCollisions };

const char* mode_name(Mode m) {
  return m == Mode::Grid ? "grid" : m == Mode::Naive ? "naive" : "no-collisions";
}

nlohmann::ordered_json run_row(std::size_t n, Mode mode, int steps, int threads) {
  omp_set_num_threads(threads);
  World world;
  PourScene scene;
  scene.spheres = n;
  scene.build(world);
  if (mode == Mode::Naive) world.solver.narrowphase = NarrowphaseMode::Naive;
  Scheduler scheduler(threads);
  PhysicsOptions physics;
  physics.collisions = mode != Mode::NoCollisions;
  add_physics_systems(scheduler, world, physics);
  FixedStepLoop loop(world, scheduler);
  std::vector<double> ms;
  for (int s = 0; s < steps; ++s) {
    auto t0 = std::chrono::steady_clock::now();
    loop.step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  double mean = 0.0;
  for (double x : ms) mean += x;
  mean /= static_cast<double>(ms.size());
  std::sort(ms.begin(), ms.end());
  nlohmann::ordered_json j;
  j["spheres"] = n;
  j["mode"] = mode_name(mode);
  j["threads"] = threads;
  j["steps"] = steps;
  j["ms_per_step_mean"] = mean;
  j["ms_per_step_median"] = ms[ms.size() / 2];
  j["pit_width_m"] = scene.pit_width();
  if (mode != Mode::NoCollisions) {
    j["grid_cells_x"] = world.grid.nx;
    j["grid_cells_z"] = world.grid.nz;
    j["grid_cells_y"] = world.grid.ny;
    j["grid_cell_m"] = world.grid.cell_size;
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Original-report tables as simulation cost per step (pour scene)"};
  std::vector<int> threads = {1, 2};
  std::size_t max_spheres = 1000000;
  std::size_t naive_max = 100000;
  int steps = 600;
  int big_steps = 60;
  std::vector<std::size_t> extension = {1000, 10000, 100000, 1000000};
  app.add_option("--threads", threads, "Thread counts, each row runs at every one")->capture_default_str();
  app.add_option("--max-spheres", max_spheres, "Largest n of the extension rows")->capture_default_str();
  app.add_option("--naive-max", naive_max, "Largest n run with the O(n^2) naive narrowphase")->capture_default_str();
  app.add_option("--steps", steps, "Steps per row up to n = 10,000 (600 = the whole pour)")->capture_default_str();
  app.add_option("--big-steps", big_steps, "Steps per row above n = 10,000 (and naive rows above 1,000)")
      ->capture_default_str();
  app.add_option("--sizes", extension, "The extension rows' n (after the original's 50..400), each up to --max-spheres")
      ->delimiter(',')
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::vector<std::size_t> sizes;
  for (std::size_t n = 50; n <= 400; n += 50) sizes.push_back(n);  // the original rows
  for (std::size_t n : extension)
    if (n <= max_spheres) sizes.push_back(n);
  for (std::size_t n : sizes) {
    try {
      refuse_if_too_big(n, "n =");
    } catch (const Error& e) {
      nlohmann::ordered_json j;
      j["spheres"] = n;
      j["refused"] = e.what();
      std::cout << j.dump() << std::endl;
      std::fprintf(stderr, "[seed_tables] n = %zu not run: %s\n", n, e.what());
      continue;
    }
    for (Mode mode : {Mode::Grid, Mode::Naive, Mode::NoCollisions}) {
      if (mode == Mode::Naive && n > naive_max) continue;
      int s = n > 10000 ? big_steps : steps;
      // Naive cost is n^2 from the first step on: a few steps measure it.
      if (mode == Mode::Naive && n > 1000) s = std::min(s, n > 10000 ? 3 : big_steps);
      for (int t : threads) {
        std::cout << run_row(n, mode, s, t).dump() << std::endl;
        std::fprintf(stderr, "[seed_tables] n = %zu %s, %d thread(s) done\n", n, mode_name(mode), t);
      }
    }
  }
  return 0;
}
