// Integration: velocities from gravity and damping, positions from velocities (symplectic
// Euler, which keeps resting contacts exactly at rest). The solver calls these kernels once per
// substep; IntegrateSystem runs them alone for scenes with no collisions at all.
// Reads: gravity, inverse mass, sleep. Writes: positions, velocities, angular velocities.
#pragma once

#include "engine/math.h"
#include "engine/system.h"

namespace ballpit {

class SphereTable;
struct SolverSettings;

// v += g h (then damping) for every awake sphere.
void integrate_velocities(SphereTable& spheres, const Vec3& gravity, float h, const SolverSettings& s);
// x += v h for every awake sphere.
void integrate_positions(SphereTable& spheres, float h);

class IntegrateSystem : public System {
 public:
  std::string_view name() const override { return "integrate"; }
  Access access() const override;
  void run(World& world) override;
};

}  // namespace ballpit
