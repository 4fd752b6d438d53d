// Integration: velocities from gravity and damping, positions from velocities. A sphere in
// free flight moves on the exact parabola (x += v h - g h^2 / 2, with v already kicked); one
// that a contact pushed this substep moves by symplectic Euler (x += v h), which keeps resting
// contacts exactly at rest. The solver runs the SolverBodies overloads once per substep on its
// own copy of the state (systems/solver_bodies.h); IntegrateSystem runs the SphereTable ones
// alone for scenes with no collisions at all.
// Reads: gravity, inverse mass, sleep. Writes: positions, velocities, angular velocities.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "engine/math.h"
#include "engine/system.h"
#include "systems/solver_bodies.h"

namespace ballpit {

class SphereTable;
struct SolverSettings;

// v += g h (then damping) for every awake sphere.
void integrate_velocities(SphereTable& spheres, const Vec3& gravity, float h, const SolverSettings& s);
// Moves every awake sphere by one substep h. `pushed` (one byte per row, or empty) marks the
// spheres a contact acted on this substep; the others are in free flight under `gravity`.
// `push_out` (or empty) adds each row's push-out velocity for this move only.
void integrate_positions(SphereTable& spheres, float h, const Vec3& gravity,
                         std::span<const std::uint8_t> pushed = {}, std::span<const Vec3> push_out = {});

// The same on rows [first, last) of the solver's bodies, on the calling thread (each thread of
// the solver moves its own rows just before its sweep reaches them, systems/solver.cpp). The
// bodies also carry the substep's flags: the velocity kick clears each body's pushed flag and
// push-out velocity for the substep ahead; the move reads them.
void integrate_velocities(SolverBodies& bodies, std::size_t first, std::size_t last, const Vec3& gravity, float h,
                          const SolverSettings& s);
void integrate_positions(SolverBodies& bodies, std::size_t first, std::size_t last, float h, const Vec3& gravity);

class IntegrateSystem : public System {
 public:
  std::string_view name() const override { return "integrate"; }
  Access access() const override;
  void run(World& world) override;
  bool data_parallel() const override { return true; }
};

}  // namespace ballpit
