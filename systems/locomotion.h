// Locomotion: idle, walk and run played as one blend driven by ground speed, with the cyclic
// clips kept in phase. Gaits are measured from the clips at spawn; each step the speed picks
// the blend weights and how fast the shared phase advances.
// Reads: a model's skeleton and clips. Writes: nothing (pure functions).
// Decision: walk and run share one normalised cycle, each clip's time being its own fraction
// of it shifted so the reference foot touches down at phase 0 in every clip (as ozz's
// samples/blend syncs clips); the phase advances at ground speed / blended stride length, so
// the planted foot stays still at any speed, and the legs never jump between poses.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/character.h"
#include "engine/model.h"

namespace ballpit {

// Foot joints: bone joints with no bone below them whose rest position lies in the lowest
// kFootHeightFraction of the model's height. Falls back to the lowest bone if none qualifies.
inline constexpr float kFootHeightFraction = 0.15f;
std::vector<std::uint16_t> find_feet(const Model& model);

// Height above the lowest it reaches in a cycle within which a foot counts as on the ground
// (unit: m): a sole's roll from heel to toe lifts the foot joint less than this, a swing more.
inline constexpr float kGroundContact = 0.015f;

// Gait of a clip: its ground speed is the speed at which the planted foot slides least, for
// each metre travelled, over one cycle, in metres for the given scale (played at the rate that
// follows ground speed, that fraction is the same at any speed); the planted foot is the foot that
// moves least over the ground (for the Wuson foot height does not tell: its hooves tip toe-down
// in the swing and dip below the planted ones). `forward` is the model's facing axis; the
// touchdown is when feet[0] is furthest forward. A single-pose clip has speed 0. A clip whose
// root motion was taken out (Clip::root_speed > 0) has that travel's speed (x scale) as its
// gait speed, the authored figure, and its slip at that speed.
Gait measure_gait(const Model& model, std::size_t clip, std::span<const std::uint16_t> feet, float scale,
                  const Vec3& forward);

// Blend weights of idle, walk and run at ground speed |speed| (unit: m/s): idle -> walk
// between 0 and the walk gait's speed, walk -> run up to the run gait's speed, run beyond.
// They are >= 0 and sum to 1 up to one rounding of a subtraction.
std::array<float, kRoles> locomotion_weights(float speed, const std::array<Gait, kRoles>& gaits);

// Phase advance (unit: cycles/s, the sign of speed) that keeps the planted foot still: ground
// speed over the blended stride (speed x cycle of each clip, weighted). Between idle and walk
// the walk's weight shrinks its stride with the speed, so the cycle keeps the walk's own rate.
float phase_rate(float speed, const std::array<float, kRoles>& weights, const std::array<Gait, kRoles>& gaits);

// A role clip's time at the shared phase (unit: s).
float role_clip_time(const Gait& gait, float phase);

}  // namespace ballpit
