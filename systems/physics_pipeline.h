// The physics step as systems, added in pipeline order: wake, grid, narrowphase, solver
// (whose substeps integrate), sleeping. The scheduler derives the dependencies from each system's
// declared access; this list only says which systems a world needs: a world without
// collisions gets a bare integrator, a world without sleeping no sleep system.
#pragma once

namespace ballpit {

class Scheduler;
class World;

struct PhysicsOptions {
  bool collisions = true;
};

void add_physics_systems(Scheduler& scheduler, const World& world, const PhysicsOptions& options = {});

}  // namespace ballpit
