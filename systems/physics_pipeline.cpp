#include "systems/physics_pipeline.h"

#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/grid.h"
#include "systems/integrate.h"
#include "systems/narrowphase.h"
#include "systems/sleeping.h"
#include "systems/solver.h"

namespace ballpit {

void add_physics_systems(Scheduler& scheduler, const World& world, const PhysicsOptions& options) {
  if (!options.collisions) {
    scheduler.emplace<IntegrateSystem>();
    return;
  }
  if (world.solver.sleeping) scheduler.emplace<WakeSystem>();
  scheduler.emplace<GridSystem>();
  scheduler.emplace<NarrowphaseSystem>();
  scheduler.emplace<SolverSystem>();
  if (world.solver.sleeping) scheduler.emplace<SleepSystem>();
}

}  // namespace ballpit
