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

// One step of the solver with `substeps` substeps (0: the world's own, the default's four).
auto solver_step(int substeps) {
  return [substeps](benchmark::State& state, World& world, std::size_t n) {
    if (substeps > 0) world.solver.substeps = substeps;
    SolverScratch scratch;
    timed_loop(state, n, [&] { solve_contacts(world, scratch); });
    state.counters["contacts"] = static_cast<double>(contact_count(world));
    state.counters["substeps"] = world.solver.substeps;
  };
}

[[maybe_unused]] const bool kSolver = register_system("solver", solver_step(0));
// The same step with one substep. A step of S substeps costs about F + S x P, so this figure
// and the one above split the solver's cost into P, a substep's passes, and F, the work done
// once a step however many substeps it has (copying the bodies in and out, packing the
// contacts into batches, writing impulses back and the warm-start cache).
[[maybe_unused]] const bool kSolverOneSubstep = register_system("solver_one_substep", solver_step(1));

}  // namespace
}  // namespace ballpit::profiling
