// Substep control alone (`--tolerance`): the overlap measure over every contact of the prepared
// world, then the decision. This is what tolerance mode adds to a step besides the substeps it
// picks. The tolerance is set out of reach so every call measures the same contacts and keeps
// the same substeps.
#include "profiling/bench_common.h"
#include "systems/substep_control.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kSubstepControl =
    register_system("substep_control", [](benchmark::State& state, World& world, std::size_t n) {
      SubstepControlSettings settings;
      settings.tolerance_r = 1.0;
      settings.calm_steps = 1 << 30;  // never lowers: the same work every call
      SubstepControlSystem control(settings);
      timed_loop(state, n, [&] { control.run(world); });
      state.counters["contacts"] = static_cast<double>(contact_count(world));
      state.counters["overlap_r"] = control.stats().max_overlap_r;
    });

}  // namespace
}  // namespace ballpit::profiling
