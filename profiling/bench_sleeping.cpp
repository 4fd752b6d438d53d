// The sleep update alone, on an awake pit: wake checks over every contact, then the stillness
// clock of every sphere. sleep_time is set out of reach so no sphere ever falls asleep and every
// call does the same work: the cost the system adds to a step while the pit is still moving.
// (A sleeping pile costs less: sleepers skip the clock and their pairs are not generated.)
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

}  // namespace
}  // namespace ballpit::profiling
