// The sleep update alone, in its two regimes, and the wake check.
// - sleeping (awake pit): sleep_time is out of reach, so no sphere is ever ready to sleep: the
//   wake requests and the stillness clock of every sphere, and the early out that skips the
//   piles. The cost the system adds to a step while the pit is still moving.
// - sleeping_piles (a still pit falling asleep): every sphere has been still for sleep_time,
//   so each call builds the piles (a union-find over every loaded pair of the warm-start cache)
//   and puts the whole pit to sleep; the loop then wakes it again by clearing the sleep flags
//   (a memset, timed with it). The cost of a step in which piles may change: one is ready to
//   sleep, or something moves while something sleeps. A pit asleep whole skips the piles.
#include <algorithm>
#include <limits>

#include "profiling/bench_common.h"
#include "systems/sleeping.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kSleeping = register_system("sleeping", [](benchmark::State& state, World& world, std::size_t n) {
  world.solver.sleeping = true;
  world.solver.sleep_time = std::numeric_limits<float>::max();
  timed_loop(state, n, [&] { update_sleep(world); });
  state.counters["contacts"] = static_cast<double>(contact_count(world));
});

[[maybe_unused]] const bool kSleepingPiles =
    register_system("sleeping_piles", [](benchmark::State& state, World& world, std::size_t n) {
      world.solver.sleeping = true;
      // At rest (the lattice's settling leaves it creeping faster than sleep_speed) and still
      // for long enough.
      auto v = world.spheres.mut_velocity();
      std::fill(v.begin(), v.end(), Vec3::Zero());
      if (world.spheres.has_angular()) {
        auto w = world.spheres.mut_angular_velocity();
        std::fill(w.begin(), w.end(), Vec3::Zero());
      }
      auto still = world.spheres.mut_still_time();
      std::fill(still.begin(), still.end(), world.solver.sleep_time);
      auto asleep = world.spheres.mut_asleep();
      timed_loop(state, n, [&] {
        std::fill(asleep.begin(), asleep.end(), std::uint8_t{0});
        update_sleep(world);
      });
      if (static_cast<std::size_t>(std::count(asleep.begin(), asleep.end(), std::uint8_t{1})) != n)
        state.SkipWithError("the pit did not fall asleep whole");
      state.counters["cache_entries"] = static_cast<double>(world.contacts.warm.size());
    });

// The wake check alone on an awake pit: every contact is looked at and nothing wakes (no
// sphere sleeps), the cost the wake system adds to each step of a pit that is moving.
[[maybe_unused]] const bool kWake = register_system("wake", [](benchmark::State& state, World& world, std::size_t n) {
  world.solver.sleeping = true;
  timed_loop(state, n, [&] { wake_approached(world); });
  state.counters["contacts"] = static_cast<double>(contact_count(world));
});

}  // namespace
}  // namespace ballpit::profiling
