// The contact solver alone: all substeps of one step (each integrates, warm-starts, solves,
// moves and relaxes) over the contacts the narrowphase found when the world was prepared,
// including the packing of those contacts into batches and the impulses written back.
// Repeated calls keep that contact list, which stays right for a resting pile: its contacts
// persist from step to step; the solver recomputes every gap and normal from the positions. The
// scratch (the solver's body records and batches) is kept between calls, as SolverSystem keeps
// it between steps.
#include "profiling/bench_common.h"
#include "systems/solver.h"

namespace ballpit::profiling {
namespace {

[[maybe_unused]] const bool kSolver = register_system("solver", [](benchmark::State& state, World& world, std::size_t n) {
  SolverScratch scratch;
  timed_loop(state, n, [&] { solve_contacts(world, scratch); });
  state.counters["contacts"] = static_cast<double>(contact_count(world));
  state.counters["substeps"] = world.solver.substeps;
});

}  // namespace
}  // namespace ballpit::profiling
