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

// The same world with one sphere in twenty flung at 3 m/s, as a running character flings them:
// each of those searches a wider box all around (a margin past the grid's one-cell reach).
[[maybe_unused]] const bool kNarrowphaseFlung =
    register_system("narrowphase_flung", [](benchmark::State& state, World& world, std::size_t n) {
      auto v = world.spheres.mut_velocity();
      for (std::size_t i = 0; i < v.size(); i += 20) v[i] = 3.0f * Vec3(1.8f, 2.0f, -1.2f).normalized();
      NarrowphaseScratch scratch;
      timed_loop(state, n, [&] { find_contacts(world, scratch); });
      state.counters["contacts"] = static_cast<double>(contact_count(world));
    });

// One sphere in twenty fired at 100 m/s (issue 40's volley), searched in one step of 1/60 s as a
// pass too long for them would: their margins, 42 r uncapped, are held to the cap (2.5 r,
// engine/speculative_margin.h), so each lists at most its near neighbours. Set against
// narrowphase_flung, it shows what the cap leaves of the wide search.
[[maybe_unused]] const bool kNarrowphaseFired =
    register_system("narrowphase_fired", [](benchmark::State& state, World& world, std::size_t n) {
      auto v = world.spheres.mut_velocity();
      for (std::size_t i = 0; i < v.size(); i += 20) v[i] = Vec3(0.0f, -100.0f, 0.0f);
      NarrowphaseScratch scratch;
      timed_loop(state, n, [&] { find_contacts(world, scratch); });
      state.counters["contacts"] = static_cast<double>(contact_count(world));
    });

}  // namespace
}  // namespace ballpit::profiling
