// Animation: each step, advances every character's locomotion (blend weights from ground
// speed, the shared phase at the rate that keeps the planted foot still), samples the clips
// that have weight, blends them, lays an action (jump, kick) over them when one plays, and
// poses the skeleton at the end of the step. It also
// measures foot slip: the horizontal world speed of the lowest foot while the character moves.
// Reads: CharacterController (ground speed, root at both ends of the step). Writes: CharacterPose.
// Decision: the pose at the start of the step is last step's end pose, kept rather than
// resampled, so each pose is sampled once; with the new end pose the joint colliders get their
// motion over exactly the coming step (the animation sampled at t and t + dt).
#pragma once

#include "engine/character.h"
#include "engine/system.h"

namespace ballpit {

// Ground speeds below this count as standing still for foot slip: the walk cycle's slowest
// blends shuffle in place and their slip says nothing about the playback rate (unit: m/s).
inline constexpr float kSlipMinSpeed = 0.05f;

// An action (jump, kick) fades in and out over this long, so it starts and ends on the
// locomotion pose it interrupts without a jump of any joint (unit: s).
inline constexpr float kActionFade = 0.2f;

// Weight of an action clip `time` into it: smoothstep up over the first kActionFade and down
// over the last, never above 1 (a clip shorter than two fades peaks lower).
float action_weight(float time, float duration);

// Poses the character at motion.current with its current phase, as both start and end of the
// step (spawn, or a teleport).
void reset_pose(const CharacterSetup& setup, const CharacterMotion& motion, CharacterPose& pose);

// One step of dt (unit: s): phase, weights, sampling, blend, model transforms, foot slip.
void advance_pose(const CharacterSetup& setup, const CharacterMotion& motion, CharacterPose& pose, float dt);

class AnimationSystem : public System {
 public:
  std::string_view name() const override { return "animation"; }
  Access access() const override;
  void run(World& world) override;
};

}  // namespace ballpit
