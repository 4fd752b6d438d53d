// Joint-collider guard: once after the solver's last substep, no sphere may be left inside a
// joint collider where the step leaves it. A collider has infinite mass, so it must win: in a
// jam (a hoof pressing a ball into the pile) the contacts cannot all hold, and the spheres'
// overlap takes the rest, which their push-out spreads over the next step. Once per step, not
// per substep: a guard inside the substeps kept re-creating the approach that the pair impacts
// then bounced (measured: balls at 14 m/s off a 1 m/s hoof).
//
// Every sphere near a collider is checked, not only those the narrowphase paired with one: a
// ball struck mid-step by another can cross more than its speculative margin and reach a limb
// it had no contact with. Such a ball may be deep in the capsule or already through it, where
// the nearest surface is the far one. So the guard follows each sphere's path over the step,
// seen from the collider (its start carried along with the collider's surface): a path that
// crossed to the far side of the capsule's axis puts the sphere back where it entered; any
// other overlap is pushed out along the nearest normal. Either way the sphere's approach to the
// surface is removed. A sphere pinched between two colliders, which those pushes only pass back
// and forth, leaves by the shortest move that clears both. Each sphere is guarded alone, so the
// result is the same for any number of threads.
//
// In the 100k pit-character run (300 + 600 steps) the guard of the listed contacts alone left
// up to 3 balls inside a collider after a step, the deepest (0.26 r) pinched between two limbs;
// this one leaves none deeper than 1e-4 r (profiling/reports/character.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "engine/collider_table.h"
#include "engine/math.h"
#include "systems/solver_bodies.h"

namespace ballpit {

// `start`: each sphere's position when the step began; `bodies`: where the substeps left them
// (position, radius, velocity), corrected in place. Colliders are posed at `dt` into the step.
// Returns the rows it moved, in ascending order (a sleeper among them is stored back although
// the solver stores only the awake rows).
std::vector<std::uint32_t> guard_colliders(const ColliderTable& colliders, float dt, std::span<const Vec3> start,
                                           SolverBodies& bodies);

// Closest points of segments [p0, p1] and [q0, q1], as their parameters (s, t) in [0, 1].
struct SegmentParameters {
  float s, t;
};
SegmentParameters closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

}  // namespace ballpit
