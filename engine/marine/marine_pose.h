// A pose of the marine made the way an animator makes one: the hips placed in the model's
// space, every joint's orientation given in model space (not relative to its parent), legs
// solved by two-bone IK so a foot lands exactly where it is asked to. It becomes one frame of
// local keys for a Clip.
// Decision: orientations are kept in model space while a pose is built, since gait data and
// foot placement speak of segments against the ground (a shank's tilt, a foot's pitch), then
// turned into parent-relative rotations once, at the end (bind rotations are the identity).
#pragma once

#include <array>

#include "engine/clip.h"
#include "engine/marine/marine_skeleton.h"
#include "engine/math.h"
#include "engine/skeleton.h"

namespace ballpit::marine {

// Rotations about the model axes by an angle (unit: rad), right-handed: about x a positive
// angle turns +y toward +z (a trunk leaning forward), about y turns +z toward +x (a left
// turn), about z turns +x toward +y.
Quat about_x(float angle);
Quat about_y(float angle);
Quat about_z(float angle);

// The heel's underside relative to the ankle in the bind pose.
inline const Vec3 kHeelFromAnkle(0.0f, -kAnkleHeight, -0.06f);

// A foot's model orientation for a pitch (unit: rad): positive lifts the toes, negative the heel.
Quat foot_pitch(float pitch);
// Where the ankle is when the foot, pitched so, rests its heel on `ground`, or, with the heel
// up, pivots about the toes' joint (ToeBase) at `toe_joint`, the toes flat on the ground: the
// foot rolls about that joint, so it holds still however far the heel rises.
Vec3 ankle_over_heel(const Vec3& ground, float pitch);
Vec3 ankle_from_toe_joint(const Vec3& toe_joint, float pitch);
// The toes' joint of a flat foot standing with its heel on `heel_ground`.
Vec3 toe_joint_of_flat_foot(const Vec3& heel_ground);

// Arms held out from his sides by this much at least (unit: rad): his hands then pass his
// thighs more than a pit ball's diameter (8 cm) apart, so no ball is pinched between two limbs,
// where neither could push it out (two immovable surfaces closer than a ball's width must
// overlap it).
inline constexpr float kArmClearance = 0.32f;

// Each foot's distance from his midline when he stands, walks or runs (unit: m): wider than
// the bind pose's hips, so his shins and boots stand and pass more than a ball's diameter
// apart, for the same reason.
inline constexpr float kStanceTrack = 0.125f;

struct MarinePose {
  Vec3 hips = Vec3::Zero();  // Hips joint position (unit: m)
  std::array<Quat, kJoints> world;  // model-space orientation of each joint

  // The standing bind pose: hips at their bind height, every orientation the identity.
  static MarinePose bind();

  // Model-space position of every joint (forward kinematics).
  std::array<Vec3, kJoints> positions() const;

  // Knee angle (unit: rad) the leg IK keeps at least, so a leg never locks straight and the
  // knee's bending direction stays defined.
  static constexpr float kMinKneeFlexion = 0.07f;
  // Farthest hip-to-ankle distance the IK reaches, with the knee bent kMinKneeFlexion (unit: m).
  static float leg_reach();

  // Places the ankle (Foot joint) of a leg at `ankle` with the foot's model orientation `foot`
  // and the toes' `toe`; the knee bends toward `pole` (a model-space direction, usually
  // forward). Thigh and shin are solved by two-bone IK from where the hips put the hip joint;
  // an ankle out of reach is reached toward as far as the knee limit allows.
  void place_leg(bool left, const Vec3& ankle, const Quat& foot, const Quat& toe, const Vec3& pole);

  // An arm hanging from the shoulder: `flexion` swings it forward (unit: rad, negative: back),
  // `abduction` lifts it sideways from hanging straight down, `elbow` bends the forearm
  // forward, all relative to the chest's orientation (Spine2).
  void place_arm(bool left, float flexion, float abduction, float elbow);

  // Writes this pose as key k (time t, unit: s) of every track of the clip: the hips'
  // translation and every joint's rotation relative to its parent.
  void key(Clip& clip, float t) const;
};

// A clip with every track empty but the rest translations and unit scales of the skeleton,
// ready for MarinePose::key to append frames.
Clip empty_clip(const Skeleton& skeleton, const char* name, float duration, bool looping);

}  // namespace ballpit::marine
