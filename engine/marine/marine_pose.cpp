#include "engine/marine/marine_pose.h"

#include <algorithm>
#include <cmath>

namespace ballpit::marine {

namespace {

constexpr std::array<int, kJoints> parents() {
  return {-1,      kHips,          kSpine,    kSpine1,      kSpine2,   kNeck,
          kSpine2, kLeftShoulder,  kLeftArm,  kLeftForeArm,
          kSpine2, kRightShoulder, kRightArm, kRightForeArm,
          kHips,   kLeftUpLeg,     kLeftLeg,  kLeftFoot,
          kHips,   kRightUpLeg,    kRightLeg, kRightFoot};
}

// The rotation taking the orthonormal frame (a, b) to (c, d): a -> c exactly, b -> d as near as
// the first allows.
Quat frame_to_frame(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  auto frame = [](Vec3 x, Vec3 y) {
    x.normalize();
    y = (y - y.dot(x) * x).normalized();
    Mat3 m;
    m.col(0) = x;
    m.col(1) = y;
    m.col(2) = x.cross(y);
    return m;
  };
  return Quat(frame(c, d) * frame(a, b).transpose()).normalized();
}

Vec3 offset(int j) {
  static const std::array<Vec3, kJoints> p = bind_positions();
  const int parent = parents()[j];
  return parent < 0 ? p[j] : Vec3(p[j] - p[parent]);
}

}  // namespace

Quat about_x(float angle) { return Quat(Eigen::AngleAxisf(angle, Vec3::UnitX())); }
Quat about_y(float angle) { return Quat(Eigen::AngleAxisf(angle, Vec3::UnitY())); }
Quat about_z(float angle) { return Quat(Eigen::AngleAxisf(angle, Vec3::UnitZ())); }

Quat foot_pitch(float pitch) { return about_x(-pitch); }
Vec3 ankle_over_heel(const Vec3& ground, float pitch) { return ground - foot_pitch(pitch) * kHeelFromAnkle; }
Vec3 ankle_from_toe_joint(const Vec3& toe_joint, float pitch) {
  return toe_joint - foot_pitch(pitch) * Vec3(0.0f, kToeBaseHeight - kAnkleHeight, kFootForward);
}
Vec3 toe_joint_of_flat_foot(const Vec3& heel_ground) {
  return heel_ground - kHeelFromAnkle + Vec3(0.0f, kToeBaseHeight - kAnkleHeight, kFootForward);
}

MarinePose MarinePose::bind() {
  MarinePose p;
  p.hips = bind_positions()[kHips];
  p.world.fill(Quat::Identity());
  return p;
}

std::array<Vec3, kJoints> MarinePose::positions() const {
  std::array<Vec3, kJoints> x;
  x[kHips] = hips;
  for (int j = 1; j < kJoints; ++j) {
    const int parent = parents()[j];
    x[j] = x[parent] + world[parent] * offset(j);
  }
  return x;
}

float MarinePose::leg_reach() {
  const float a = offset(kLeftLeg).norm(), b = offset(kLeftFoot).norm();
  return std::sqrt(a * a + b * b + 2.0f * a * b * std::cos(kMinKneeFlexion));
}

void MarinePose::place_leg(bool left, const Vec3& ankle, const Quat& foot, const Quat& toe, const Vec3& pole) {
  const int up = left ? kLeftUpLeg : kRightUpLeg;
  const Vec3 thigh0 = offset(up + 1), shin0 = offset(up + 2);
  const float l1 = thigh0.norm(), l2 = shin0.norm();
  const Vec3 hip = hips + world[kHips] * offset(up);
  Vec3 to_ankle = ankle - hip;
  const float d = std::clamp(to_ankle.norm(), std::abs(l1 - l2) + 1e-4f, leg_reach());
  const Vec3 u = to_ankle.normalized();
  Vec3 v = pole - pole.dot(u) * u;  // toward the knee, square to the hip-ankle line
  v = v.norm() > 1e-6f ? Vec3(v.normalized()) : Vec3(u.unitOrthogonal());
  const float cos_hip = std::clamp((l1 * l1 + d * d - l2 * l2) / (2.0f * l1 * d), -1.0f, 1.0f);
  const float sin_hip = std::sqrt(1.0f - cos_hip * cos_hip);
  const Vec3 knee = hip + l1 * (cos_hip * u + sin_hip * v);
  const Vec3 reached = hip + d * u;
  // The knee's hinge is the normal of the leg's plane; in the bind pose (leg down, pole
  // forward) that is the same cross product of the bind vectors, so the frames match.
  const Vec3 hinge = u.cross(v);
  const Vec3 bind_hinge = thigh0.normalized().cross(Vec3::UnitZ());
  world[up] = frame_to_frame(thigh0, bind_hinge, knee - hip, hinge);
  world[up + 1] = frame_to_frame(shin0, bind_hinge, reached - knee, hinge);
  world[up + 2] = foot;
  world[up + 3] = toe;
}

void MarinePose::place_arm(bool left, float flexion, float abduction, float elbow) {
  const int arm = left ? kLeftArm : kRightArm;
  const float side = left ? 1.0f : -1.0f;
  const Quat chest = world[kSpine2];
  world[arm - 1] = chest;  // clavicle rides with the chest
  // Bind: the arm points out and 45 degrees down; hanging, it points down and a little out.
  const Vec3 bind_dir = offset(arm + 1).normalized();
  const Vec3 hang(side * std::sin(abduction), -std::cos(abduction), 0.0f);
  const Quat hang_rot = Quat::FromTwoVectors(bind_dir, hang);
  // Flexion about the chest's x axis carries the arm forward (-y toward +z): a negative angle.
  world[arm] = chest * about_x(-flexion) * hang_rot;
  // The elbow bends the forearm forward about the same axis.
  world[arm + 1] = chest * about_x(-flexion - elbow) * hang_rot;
  world[arm + 2] = world[arm + 1];
}

void MarinePose::key(Clip& clip, float t) const {
  static constexpr auto p = parents();
  for (int j = 0; j < kJoints; ++j) {
    JointTrack& track = clip.tracks[static_cast<std::size_t>(j)];
    Quat local = p[j] < 0 ? world[j] : Quat(world[p[j]].conjugate() * world[j]);
    local.normalize();
    // One hemisphere along the track, so slerp between keys never takes the long way.
    if (!track.rotations.empty() && track.rotations.back().dot(local) < 0.0f) local.coeffs() = -local.coeffs();
    track.rotation_times.push_back(t);
    track.rotations.push_back(local);
  }
  JointTrack& root = clip.tracks[kHips];
  root.translation_times.push_back(t);
  root.translations.push_back(hips);
}

Clip empty_clip(const Skeleton& skeleton, const char* name, float duration, bool looping) {
  Clip clip;
  clip.name = name;
  clip.duration = duration;
  clip.ticks_per_second = 60.0f;
  clip.looping = looping;
  clip.tracks.resize(skeleton.size());
  for (std::size_t j = 0; j < skeleton.size(); ++j) {
    JointTrack& t = clip.tracks[j];
    if (j != kHips) {
      t.translation_times = {0.0f};
      t.translations = {skeleton.rest_translation[j]};
    }
    t.scale_times = {0.0f};
    t.scales = {Vec3::Ones()};
  }
  return clip;
}

}  // namespace ballpit::marine
