// hello_pit: pours a few thousand balls into a pit, steps 2 s, and prints the report.
//   hello_pit [SPHERES] [SCENE]   (defaults: 2000, the built-in "pour"; SCENE may be a .json file)
// The same scene and steps through `ballpit run --scene pour --set populations.0.count=2000
// --set steps=120` print the same state_hash.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "api/ballpit.h"

int main(int argc, char** argv) {
  const std::string spheres = argc > 1 ? argv[1] : "2000";
  const std::string scene = argc > 2 ? argv[2] : "pour";
  try {
    ballpit::Simulation sim = ballpit::Simulation::from_scene(scene, {"populations.0.count=" + spheres});
    const int steps = static_cast<int>(2.0 / sim.dt() + 0.5);  // 2 s of fixed steps

    const auto start = std::chrono::steady_clock::now();
    sim.step(steps);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const ballpit::Report r = sim.report();
    std::printf("ballpit %s: %zu balls, %d steps of %.4f s in %.2f s (%.2f ms a step)\n", ballpit::version().c_str(),
                r.spheres, steps, r.dt, wall_s, 1000.0 * wall_s / steps);
    std::printf("max_penetration_r %.6f\nmean_penetration_r %.6f\nescaped %zu\nkinetic_energy_j %.6f\n",
                r.max_penetration_r, r.mean_penetration_r, r.escaped, r.kinetic_energy_j);
    for (const ballpit::SystemTiming& t : sim.timings())
      std::printf("system %-12s %8.3f ms mean %8.3f ms p95\n", t.name.c_str(), t.mean_ms, t.p95_ms);
    // The lowest ball, read straight from the engine's columns (x, y, z per row).
    const std::span<const float> p = sim.positions();
    float lowest = 1e9f;
    for (std::size_t i = 0; i < sim.sphere_count(); ++i) lowest = std::min(lowest, p[3 * i + 1]);
    std::printf("lowest_centre_m %.4f\nstate_hash %s\n", lowest, r.state_hash_hex.c_str());
  } catch (const ballpit::Error& e) {
    std::fprintf(stderr, "hello_pit: %s\n", e.what());
    return 1;
  }
}
