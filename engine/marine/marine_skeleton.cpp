#include "engine/marine/marine_skeleton.h"

#include <cmath>

namespace ballpit::marine {

const std::array<std::string_view, kJoints> kJointNames = {
    "mixamorig:Hips",          "mixamorig:Spine",        "mixamorig:Spine1",        "mixamorig:Spine2",
    "mixamorig:Neck",          "mixamorig:Head",         "mixamorig:LeftShoulder",  "mixamorig:LeftArm",
    "mixamorig:LeftForeArm",   "mixamorig:LeftHand",     "mixamorig:RightShoulder", "mixamorig:RightArm",
    "mixamorig:RightForeArm",  "mixamorig:RightHand",    "mixamorig:LeftUpLeg",     "mixamorig:LeftLeg",
    "mixamorig:LeftFoot",      "mixamorig:LeftToeBase",  "mixamorig:RightUpLeg",    "mixamorig:RightLeg",
    "mixamorig:RightFoot",     "mixamorig:RightToeBase",
};

namespace {

constexpr std::array<int, kJoints> kParents = {
    -1,      kHips,        kSpine,         kSpine1,  kSpine2,      kNeck,
    kSpine2, kLeftShoulder, kLeftArm,      kLeftForeArm,
    kSpine2, kRightShoulder, kRightArm,    kRightForeArm,
    kHips,   kLeftUpLeg,   kLeftLeg,       kLeftFoot,
    kHips,   kRightUpLeg,  kRightLeg,      kRightFoot,
};

}  // namespace

std::array<Vec3, kJoints> bind_positions() {
  std::array<Vec3, kJoints> p;
  const float pelvis = kHipHeight + 0.07f;  // the Hips joint sits between the hip joints, a little higher
  p[kHips] = Vec3(0.0f, pelvis, 0.0f);
  p[kSpine] = Vec3(0.0f, pelvis + 0.10f, -0.01f);
  p[kSpine1] = Vec3(0.0f, pelvis + 0.22f, -0.015f);
  p[kSpine2] = Vec3(0.0f, pelvis + 0.35f, -0.01f);
  p[kNeck] = Vec3(0.0f, 1.52f, -0.01f);
  p[kHead] = Vec3(0.0f, 1.61f, 0.01f);
  const Vec3 down_arm(std::cos(kArmDrop), -std::sin(kArmDrop), 0.0f);
  for (int side = 0; side < 2; ++side) {
    const float s = side == 0 ? 1.0f : -1.0f;  // left: +x
    const Vec3 arm_dir(s * down_arm.x(), down_arm.y(), 0.0f);
    const int o = side == 0 ? 0 : kRightShoulder - kLeftShoulder;
    p[kLeftShoulder + o] = Vec3(s * 0.04f, 1.45f, -0.01f);
    p[kLeftArm + o] = Vec3(s * 0.18f, 1.43f, -0.02f);
    p[kLeftForeArm + o] = p[kLeftArm + o] + kUpperArm * arm_dir;
    p[kLeftHand + o] = p[kLeftForeArm + o] + kForeArm * arm_dir;
    const int l = side == 0 ? 0 : kRightUpLeg - kLeftUpLeg;
    p[kLeftUpLeg + l] = Vec3(s * kHipHalfWidth, kHipHeight, 0.0f);
    p[kLeftLeg + l] = Vec3(s * kHipHalfWidth, kHipHeight - kThigh, 0.01f);
    p[kLeftFoot + l] = Vec3(s * kHipHalfWidth, kAnkleHeight, 0.0f);
    p[kLeftToeBase + l] = Vec3(s * kHipHalfWidth, kToeBaseHeight, kFootForward);
  }
  return p;
}

Skeleton make_skeleton() {
  const auto p = bind_positions();
  Skeleton sk;
  for (int j = 0; j < kJoints; ++j) {
    sk.names.emplace_back(kJointNames[j]);
    sk.parents.push_back(kParents[j]);
    sk.rest_translation.push_back(kParents[j] < 0 ? p[j] : Vec3(p[j] - p[kParents[j]]));
    sk.rest_rotation.push_back(Quat::Identity());
    sk.rest_scale.push_back(Vec3::Ones());
    sk.is_bone.push_back(1);
  }
  return sk;
}

bool is_left(Joint j) {
  return (j >= kLeftShoulder && j <= kLeftHand) || (j >= kLeftUpLeg && j <= kLeftToeBase);
}

Joint mirror(Joint j) {
  if (j >= kLeftShoulder && j <= kLeftHand) return static_cast<Joint>(j + (kRightShoulder - kLeftShoulder));
  if (j >= kRightShoulder && j <= kRightHand) return static_cast<Joint>(j - (kRightShoulder - kLeftShoulder));
  if (j >= kLeftUpLeg && j <= kLeftToeBase) return static_cast<Joint>(j + (kRightUpLeg - kLeftUpLeg));
  if (j >= kRightUpLeg && j <= kRightToeBase) return static_cast<Joint>(j - (kRightUpLeg - kLeftUpLeg));
  return j;
}

}  // namespace ballpit::marine
