// The marine's skeleton: 22 joints with Mixamo's names ("mixamorig:Hips", ...), so clips made
// for Mixamo characters match him joint by joint, parents first, in a bind pose a little off
// the T: arms 45 degrees down (the shoulders then deform about their middle range), legs
// straight, feet flat, facing +z with y up and his left on +x, in metres.
// Decision: every joint's bind rotation is the identity, so a local rotation in a clip is the
// same rotation in the model's axes (x: his left, y: up, z: forward). The clip makers
// (marine_clips.h) and the body (marine_body.h) rely on this.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "engine/math.h"
#include "engine/skeleton.h"

namespace ballpit::marine {

enum Joint : std::uint16_t {
  kHips, kSpine, kSpine1, kSpine2, kNeck, kHead,
  kLeftShoulder, kLeftArm, kLeftForeArm, kLeftHand,
  kRightShoulder, kRightArm, kRightForeArm, kRightHand,
  kLeftUpLeg, kLeftLeg, kLeftFoot, kLeftToeBase,
  kRightUpLeg, kRightLeg, kRightFoot, kRightToeBase,
  kJoints
};

// Mixamo's joint names, by Joint.
extern const std::array<std::string_view, kJoints> kJointNames;

// Heights and lengths of his build (unit: m). Stature is to the top of the helmet.
inline constexpr float kStature = 1.80f;
inline constexpr float kHipHeight = 0.93f;     // hip joints above the floor, standing
inline constexpr float kThigh = 0.43f;         // hip to knee
inline constexpr float kShin = 0.41f;          // knee to ankle
inline constexpr float kAnkleHeight = 0.09f;   // ankle above the floor: boot sole and heel
inline constexpr float kFootForward = 0.14f;   // ankle to the ball of the foot (ToeBase), along z
inline constexpr float kToeBaseHeight = 0.025f;  // ball of the foot above the floor
inline constexpr float kHipHalfWidth = 0.095f;
inline constexpr float kUpperArm = 0.29f;
inline constexpr float kForeArm = 0.26f;
inline constexpr float kArmDrop = 0.785398f;   // bind pose: arms 45 degrees below horizontal (unit: rad)

// Bind (model-space) position of every joint.
std::array<Vec3, kJoints> bind_positions();

// The skeleton: names, parents, rest translations (bind offsets from the parent), identity
// rotations, unit scales, every joint a bone.
Skeleton make_skeleton();

// Whether a joint is on his left (+x) side; the mirror of a left joint is the right one.
bool is_left(Joint j);
Joint mirror(Joint j);

}  // namespace ballpit::marine
