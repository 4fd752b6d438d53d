// The narrowphase alone: every sphere gathers its partners from the neighbour cells, the pit
// planes and the joint colliders into per-slab contact lists, picking up warm-start impulses.
// It reads the state and rewrites the lists, so repeated calls do the same work.
#include "profiling/bench_common.h"
#include "systems/narrowphase.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kNarrowphase = register_system("narrowphase", [](benchmark::State& state, World& world, std::size_t n) {
  NarrowphaseScratch scratch;
  timed_loop(state, n, [&] { find_contacts(world, scratch); });
  state.counters["contacts"] = static_cast<double>(contact_count(world));
});

}  // namespace
}  // namespace ballpit::profiling
