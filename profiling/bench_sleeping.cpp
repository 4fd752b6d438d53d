// Sleeping by region (systems/sleeping.h), in its regimes, and what a pit asleep costs a step.
// - sleeping (awake pit): sleep_time is out of reach, so no region is ever ready to sleep: the
//   stillness clock of every sphere and the restless marks. What the system adds to a step
//   while the pit moves.
// - sleeping_regions (a still pit falling asleep): every sphere has been still for sleep_time,
//   so each call checks every contact's depth (a region sleeps only within the bound) and puts
//   the regions within it to sleep (asleep_fraction says how much); the loop then wakes it
//   again by clearing the sleep flags (a memset, timed with it). The cost of a step in which
//   regions fall asleep.
// - wake (a pit asleep but for one sphere in a hundred, moving at 1 m/s): the regions they may
//   reach are marked and their sleepers woken; the loop puts the pit back to sleep first (a
//   memset and the movers' flags, timed with it). The cost of a step in which regions wake.
// - asleep_step: a whole physics step (wake, grid, narrowphase, solver, sleeping) of a pit
//   asleep whole: what a settled pit costs with nothing moving.
// - tenth_awake_step and awake_step: the same step with the spheres of a tenth of the floor
//   awake (a disc, as around a character) and the rest asleep, and with all awake (sleeping on,
//   nothing ready to sleep). Were every system's cost to follow the awake spheres, the first
//   would cost a tenth of the second (plus the contacts at the disc's rim).
#include <algorithm>
#include <limits>

#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "profiling/bench_common.h"
#include "systems/physics_pipeline.h"
#include "systems/sleeping.h"

namespace ballpit::profiling {
namespace {

void hold_still(World& world) {
  auto v = world.spheres.mut_velocity();
  std::fill(v.begin(), v.end(), Vec3::Zero());
  if (world.spheres.has_angular()) {
    auto w = world.spheres.mut_angular_velocity();
    std::fill(w.begin(), w.end(), Vec3::Zero());
  }
  auto still = world.spheres.mut_still_time();
  std::fill(still.begin(), still.end(), world.solver.sleep_time);
}

[[maybe_unused]] const bool kSleeping = register_system("sleeping", [](benchmark::State& state, World& world, std::size_t n) {
  world.solver.sleeping = true;
  world.solver.sleep_time = std::numeric_limits<float>::max();
  timed_loop(state, n, [&] { update_sleep(world); });
  state.counters["contacts"] = static_cast<double>(contact_count(world));
});

[[maybe_unused]] const bool kSleepingRegions =
    register_system("sleeping_regions", [](benchmark::State& state, World& world, std::size_t n) {
      world.solver.sleeping = true;
      hold_still(world);  // the lattice's settling leaves it creeping faster than sleep_speed
      auto asleep = world.spheres.mut_asleep();
      timed_loop(state, n, [&] {
        std::fill(asleep.begin(), asleep.end(), std::uint8_t{0});
        update_sleep(world);
      });
      const auto sleepers = static_cast<double>(std::count(asleep.begin(), asleep.end(), std::uint8_t{1}));
      state.counters["asleep_fraction"] = sleepers / static_cast<double>(n);
    });

[[maybe_unused]] const bool kWake = register_system("wake", [](benchmark::State& state, World& world, std::size_t n) {
  world.solver.sleeping = true;
  hold_still(world);
  auto asleep = world.spheres.mut_asleep();
  auto v = world.spheres.mut_velocity();
  std::size_t woken = 0;
  timed_loop(state, n, [&] {
    std::fill(asleep.begin(), asleep.end(), std::uint8_t{1});
    for (std::size_t i = 0; i < n; i += 100) {
      asleep[i] = 0;
      v[i] = Vec3(1.0f, 0.0f, 0.0f);
    }
    woken = wake_approached(world);
  });
  state.counters["woken_fraction"] = static_cast<double>(woken) / static_cast<double>(n);
});

[[maybe_unused]] const bool kAsleepStep =
    register_system("asleep_step", [](benchmark::State& state, World& world, std::size_t n) {
      world.solver.sleeping = true;
      hold_still(world);
      auto asleep = world.spheres.mut_asleep();
      std::fill(asleep.begin(), asleep.end(), std::uint8_t{1});
      Scheduler scheduler(omp_get_max_threads());
      add_physics_systems(scheduler, world);
      FixedStepLoop loop(world, scheduler);
      timed_loop(state, n, [&] { loop.step(); });
      if (static_cast<std::size_t>(std::count(asleep.begin(), asleep.end(), std::uint8_t{1})) != n)
        state.SkipWithError("something woke");
    });

// A full physics step with the spheres inside a disc of `awake_share` of the floor awake, the
// rest asleep, and sleep_time out of reach so that the awake part stays awake. The pattern is
// laid again before every step (a pass over the rows, timed with it, 0.05 ms at 100k): the
// awake disc settles into the sleepers around it, presses them past the bound, and would wake
// the pit whole within a few steps (the packed lattice did, and its "tenth" measured a pit all
// awake).
void step_with_awake_share(benchmark::State& state, World& world, std::size_t n, double awake_share) {
  world.solver.sleeping = true;
  hold_still(world);
  world.solver.sleep_time = std::numeric_limits<float>::max();
  const float w = world.pit.half_width;
  const float radius2 = static_cast<float>(awake_share) * 4.0f * w * w / 3.14159265f;
  auto lay_pattern = [&] {
    auto asleep = world.spheres.mut_asleep();
    auto v = world.spheres.mut_velocity();
    auto x = world.spheres.position();
    for (std::size_t i = 0; i < n; ++i) {
      asleep[i] = x[i].x() * x[i].x() + x[i].z() * x[i].z() >= radius2;
      if (asleep[i]) v[i].setZero();
    }
  };
  Scheduler scheduler(omp_get_max_threads());
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);
  timed_loop(state, n, [&] {
    lay_pattern();
    loop.step();
  });
  lay_pattern();
  auto asleep = world.spheres.asleep();
  state.counters["awake_fraction"] =
      static_cast<double>(std::count(asleep.begin(), asleep.end(), std::uint8_t{0})) / static_cast<double>(n);
}

[[maybe_unused]] const bool kTenthAwakeStep =
    register_system("tenth_awake_step", [](benchmark::State& state, World& world, std::size_t n) {
      step_with_awake_share(state, world, n, 0.1);
    });

[[maybe_unused]] const bool kAwakeStep = register_system("awake_step", [](benchmark::State& state, World& world, std::size_t n) {
  step_with_awake_share(state, world, n, 2.0);  // a disc past the corners: all of it
});

}  // namespace
}  // namespace ballpit::profiling
