// Integration alone: one velocity update (gravity, damping) and one position update over all
// spheres, what IntegrateSystem does in a scene without collisions. Inside the solver these two
// kernels run once per substep, so a step with the default 4 substeps pays this 4 times
// (included in the solver's figure).
#include "profiling/bench_common.h"
#include "systems/integrate.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kIntegrate = register_system("integrate", [](benchmark::State& state, World& world, std::size_t n) {
  IntegrateSystem integrate;
  timed_loop(state, n, [&] { integrate.run(world); });
});

}  // namespace
}  // namespace ballpit::profiling
