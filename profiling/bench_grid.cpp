// The grid broadphase alone: the parallel counting sort (build_grid), and the full system
// (sort, then permute every sphere column into cell order). After the first call the rows are
// already in cell order, as they are in a running simulation where spheres move a little per
// step, so the permutation is close to the identity and the gather runs at memory speed.
#include "profiling/bench_common.h"
#include "systems/grid.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kSort = register_system("grid_sort", [](benchmark::State& state, World& world, std::size_t n) {
  GridScratch scratch;
  timed_loop(state, n, [&] { build_grid(world.grid, world.spheres.position(), world.spheres.radius(), scratch); });
  state.counters["cells"] = static_cast<double>(world.grid.cell_count());
});

[[maybe_unused]] const bool kRebuild = register_system("grid", [](benchmark::State& state, World& world, std::size_t n) {
  GridSystem grid;
  timed_loop(state, n, [&] { grid.run(world); });
  state.counters["cells"] = static_cast<double>(world.grid.cell_count());
});

}  // namespace
}  // namespace ballpit::profiling
