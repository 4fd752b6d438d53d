// Joint colliders: fitted once from the skinned mesh when a character spawns, then moved with
// its skeleton every step into the joint-collider table the narrowphase and solver read.
// Reads: CharacterPose (joint transforms at both ends of the step), CharacterController (the
// root at both ends). Writes: Colliders.
// Decision: surface velocity is sampled from the animation at t and t + dt, (pose(t + dt) -
// pose(t)) / dt over the coming step, not a lagging difference of the last two frames. A row
// holds the pose at the step's start; the solver moves it along that velocity inside the step,
// so at the step's end each collider sits exactly where the animation puts it.
#pragma once

#include <algorithm>

#include <cstdint>
#include <vector>

#include "engine/character.h"
#include "engine/model.h"
#include "engine/system.h"

namespace ballpit {

class World;

// One shape per bone that dominates at least one vertex (its largest weight), in the bone's
// bind space. Capsules: axis along the principal direction of those vertices, radius the
// smallest about that axis that holds them all, ends as close as that radius allows; every
// such vertex is inside its capsule in the bind pose. Spheres: centred on the joint, radius the
// capsule's radius (the limb's thickness there): the report's method, which leaves gaps between
// joints along a long bone.
std::vector<BoneShape> fit_bone_shapes(const Model& model, ColliderKind kind);

// How far the colliders reach from the root over every pose of the role and action clips (sampled
// kReachSamples times per clip), in character space (unit: m). The controller keeps the
// footprint circle inside the walls, so no turn can swing a limb through one; a scene lifts
// the character by -lowest (plus clearance) so no limb dips into the floor.
inline constexpr int kReachSamples = 64;
struct ColliderReach {
  float footprint_radius = 0.0f;  // largest horizontal distance of any collider surface
  float lowest = 0.0f;            // lowest collider surface point, relative to the root
};
ColliderReach collider_reach(const CharacterSetup& setup);

// Collider ends of one character at the start and end of the step, into its table rows.
void update_colliders(World& world, std::size_t character);

class JointColliderSystem : public System {
 public:
  std::string_view name() const override { return "joint_colliders"; }
  Access access() const override;
  void run(World& world) override;
};

// Balls against colliders at the end of the step (a + velocity * dt: where the solver left the
// colliders, and where the next update puts them).
struct ColliderOverlap {
  double max_depth_r = 0.0;  // deepest ball inside a collider / ball radius (0 if none)
  std::size_t inside = 0;    // balls deeper than depth_fraction x their radius
};
// Depth beyond which a ball counts as inside: shared/SCENES.md's 1% of the radius.
inline constexpr float kInsideDepthFraction = 0.01f;
ColliderOverlap measure_collider_overlap(const World& world, float depth_fraction = kInsideDepthFraction);

// How fast and how high the colliders move: the inputs of the struck-ball bound below.
struct ColliderMotion {
  double fastest = 0.0;  // fastest collider end this step (unit: m/s)
  double highest = 0.0;  // highest collider surface at the step's end (unit: m)

  // Folds another step's motion in: the bound below takes the worst over a run.
  void widen(const ColliderMotion& step) {
    fastest = std::max(fastest, step.fastest);
    highest = std::max(highest, step.highest);
  }
};
ColliderMotion measure_collider_motion(const World& world);

// The fastest a ball may leave a character (unit: m/s). One strike by an infinite mass moving at
// v_c sends a ball off at most at (1 + e) v_c; overlap adds at most the push-out speed; from at
// most the top of the character it can then gain only what falling gives:
// v^2 <= ((1 + e) v_c + push)^2 + 2 g h.
double struck_ball_speed_bound(const ColliderMotion& over_the_run, float restitution, float push_out_speed,
                               float gravity);

}  // namespace ballpit
