#include "engine/marine/gait_cycle.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/marine/marine_pose.h"

namespace ballpit::marine {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kKeyRate = 60.0f;  // keys per second (unit: Hz)

float wrap01(float x) { return x - std::floor(x); }

float hermite(float p0, float m0, float p1, float m1, float u) {
  const float u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
}

struct FootState {
  Vec3 ankle;
  float pitch;
  bool toe_flat;  // the toes stay on the ground while the heel is up
};

// A foot s seconds into its stance (on the ground), its heel first touching at z0.
FootState stance_foot(const GaitDesign& g, float x, float z0, float s) {
  const float stance_time = g.stance * g.cycle;
  const float tau = s / stance_time;
  const Vec3 anchor(x, 0.0f, z0 - g.speed * s);  // the heel's spot, moving back at the gait speed
  FootState f{};
  if (tau < g.foot_flat) {
    const float k = 1.0f - tau / g.foot_flat;
    f.pitch = g.heel_strike_pitch * k * k;
  } else if (tau < g.heel_off) {
    f.pitch = 0.0f;
  } else {
    const float k = (tau - g.heel_off) / (1.0f - g.heel_off);
    f.pitch = -g.toe_off_pitch * k * k;
  }
  if (tau < g.heel_off) {
    f.ankle = ankle_over_heel(anchor, f.pitch);  // rolling on the heel, or flat
  } else {
    f.ankle = ankle_from_toe_joint(toe_joint_of_flat_foot(anchor), f.pitch);  // rolling over the toes
    f.toe_flat = true;
  }
  return f;
}

// A foot at cycle phase u since its own heel strike.
FootState gait_foot(const GaitDesign& g, float x, float z0, float u) {
  const float stance_time = g.stance * g.cycle, swing_time = g.cycle - stance_time;
  const float t = u * g.cycle;
  if (t <= stance_time) return stance_foot(g, x, z0, t);
  // Swing: from the stance's end state to the next stance's start, velocities matched.
  constexpr float h = 1e-3f;
  const FootState a = stance_foot(g, x, z0, stance_time), a_ = stance_foot(g, x, z0, stance_time - h);
  const FootState b = stance_foot(g, x, z0, 0.0f), b_ = stance_foot(g, x, z0, h);
  const float w = (t - stance_time) / swing_time;
  FootState f{};
  for (int i = 0; i < 3; ++i) {
    f.ankle[i] = hermite(a.ankle[i], (a.ankle[i] - a_.ankle[i]) / h * swing_time, b.ankle[i],
                         (b_.ankle[i] - b.ankle[i]) / h * swing_time, w);
  }
  const float lift = std::sin(kPi * std::pow(w, 0.5f));  // up early: the toes clear the ground at once
  f.ankle.y() += g.clearance * lift * lift;
  f.pitch = hermite(a.pitch, (a.pitch - a_.pitch) / h * swing_time, b.pitch, (b_.pitch - b.pitch) / h * swing_time, w);
  return f;
}

}  // namespace

GaitDesign walk_design() { return GaitDesign{}; }

GaitDesign run_design() {
  GaitDesign g;
  g.name = "run";
  g.speed = 3.5f;
  g.cycle = 0.70f;  // 2.9 steps a second
  g.stance = 0.36f;
  g.heel_strike_pitch = 0.05f;  // nearly flat: a runner lands on the midfoot
  g.foot_flat = 0.12f;
  g.heel_off = 0.45f;
  g.toe_off_pitch = 0.75f;
  g.mid_stance_ankle = -0.06f;
  g.clearance = 0.22f;
  g.hips_drop = 0.05f;
  g.hips_bob = 0.04f;
  g.sway = 0.01f;
  g.pelvis_yaw = 0.1f;
  g.pelvis_roll = 0.04f;
  g.lean = 0.14f;
  g.arm_swing = 0.55f;
  g.elbow = 1.35f;
  g.elbow_swing = 0.25f;
  return g;
}

Clip make_gait_clip(const Skeleton& skeleton, const GaitDesign& g) {
  const int n = static_cast<int>(std::lround(g.cycle * kKeyRate));
  Clip clip = empty_clip(skeleton, g.name, g.cycle, true);
  const float stance_time = g.stance * g.cycle;
  // The heel strikes so that the ankle passes mid_stance_ankle ahead of the hip at mid-stance.
  const float z0 = g.mid_stance_ankle + g.speed * 0.5f * stance_time - (-kHeelFromAnkle.z());
  const float standing = bind_positions()[kHips].y();
  const float mid_stance = 0.5f * g.stance;  // the left foot's; the right's half a cycle on

  struct Frame {
    MarinePose pose;
    FootState feet[2];
    float yaw;  // the pelvis's turn; the chest turns against it
  };
  std::vector<Frame> frames(static_cast<std::size_t>(n));
  std::vector<float> ceiling(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(n);
    Frame& f = frames[static_cast<std::size_t>(i)];
    f.pose = MarinePose::bind();
    // Towards the left foot when it bears the weight (its mid-stance), the right half a cycle on.
    const float over_left = std::sin(2.0f * kPi * (u - mid_stance + 0.25f));
    const float yaw = -g.pelvis_yaw * std::cos(2.0f * kPi * u);  // the left hip forward at its heel strike
    f.yaw = yaw;
    const Quat pelvis = about_y(yaw) * about_z(g.pelvis_roll * over_left) * about_x(0.3f * g.lean);
    f.pose.world[kHips] = pelvis;
    f.pose.hips.x() = g.sway * over_left;
    f.feet[0] = gait_foot(g, g.track, z0, u);
    f.feet[1] = gait_foot(g, -g.track, z0, wrap01(u - 0.5f));
    // The hips as high as they may be for both legs to reach (a planted foot must), and no
    // higher than the gait's own height: drop plus a bob that is lowest at each mid-stance.
    const float bob = 0.5f * (1.0f + std::cos(4.0f * kPi * (u - mid_stance)));
    float top = standing - g.hips_drop - g.hips_bob * bob;
    for (int side = 0; side < 2; ++side) {
      const Vec3 hip_offset = pelvis * (bind_positions()[side == 0 ? kLeftUpLeg : kRightUpLeg] - bind_positions()[kHips]);
      const Vec3 a = f.feet[side].ankle;
      const float reach = 0.999f * MarinePose::leg_reach();
      const float dx = a.x() - (f.pose.hips.x() + hip_offset.x()), dz = a.z() - hip_offset.z();
      const float across = std::min(dx * dx + dz * dz, reach * reach);
      top = std::min(top, a.y() + std::sqrt(reach * reach - across) - hip_offset.y());
    }
    ceiling[static_cast<std::size_t>(i)] = top;
  }
  // A smooth height under the ceiling: the least ceiling over a window, then a Hann-weighted
  // mean of those over the same window. Every term of the mean is a least over a window that
  // holds the frame itself, so the mean never rises above the frame's ceiling.
  const int w = std::max(2, n / 20);
  std::vector<float> least(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    float m = ceiling[static_cast<std::size_t>(i)];
    for (int k = -w; k <= w; ++k) m = std::min(m, ceiling[static_cast<std::size_t>((i + k + n) % n)]);
    least[static_cast<std::size_t>(i)] = m;
  }
  for (int i = 0; i < n; ++i) {
    float sum = 0.0f, weights = 0.0f;
    for (int k = -w; k <= w; ++k) {
      const float c = 0.5f + 0.5f * std::cos(kPi * static_cast<float>(k) / static_cast<float>(w + 1));
      sum += c * least[static_cast<std::size_t>((i + k + n) % n)];
      weights += c;
    }
    frames[static_cast<std::size_t>(i)].pose.hips.y() = sum / weights;
  }

  for (int i = 0; i < n; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(n);
    MarinePose& p = frames[static_cast<std::size_t>(i)].pose;
    const float yaw = frames[static_cast<std::size_t>(i)].yaw;
    p.world[kSpine] = about_y(0.4f * yaw) * about_x(0.5f * g.lean);
    p.world[kSpine1] = about_x(g.lean);
    p.world[kSpine2] = about_y(-0.8f * yaw) * about_x(g.lean);  // the chest turns against the pelvis
    p.world[kNeck] = about_y(-0.3f * yaw) * about_x(0.5f * g.lean);
    p.world[kHead] = about_x(0.2f * g.lean);  // eyes level, ahead
    for (int side = 0; side < 2; ++side) {
      const FootState& f = frames[static_cast<std::size_t>(i)].feet[side];
      const Quat foot = foot_pitch(f.pitch);
      // The toes stay flat while the heel is up, and follow the foot once it swings.
      const float swing = wrap01(u - 0.5f * static_cast<float>(side)) * g.cycle - stance_time;
      const float follow = f.toe_flat ? 0.0f
                           : swing < 0.0f ? 1.0f
                                          : std::clamp(swing / (0.25f * (g.cycle - stance_time)), 0.0f, 1.0f);
      const Quat toe = Quat::Identity().slerp(follow * follow * (3.0f - 2.0f * follow), foot);
      p.place_leg(side == 0, f.ankle, foot, toe, about_y(yaw) * Vec3::UnitZ());
      // Each arm swings with the opposite leg: the left arm is back as the left heel strikes.
      const float s = side == 0 ? -1.0f : 1.0f;
      const float flexion = s * g.arm_swing * std::cos(2.0f * kPi * u);
      const float forward = g.arm_swing > 0.0f ? 0.5f + 0.5f * flexion / g.arm_swing : 0.5f;
      p.place_arm(side == 0, flexion, g.arm_abduction, g.elbow + g.elbow_swing * forward);
    }
    p.key(clip, static_cast<float>(i) * g.cycle / static_cast<float>(n));
  }
  return clip;
}

}  // namespace ballpit::marine
