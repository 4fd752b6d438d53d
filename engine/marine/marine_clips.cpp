#include "engine/marine/marine_clips.h"

#include <algorithm>
#include <cmath>

#include "engine/marine/gait_cycle.h"
#include "engine/marine/key_curve.h"
#include "engine/marine/marine.h"
#include "engine/marine/marine_pose.h"

namespace ballpit::marine {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kKeyRate = 60.0f;   // keys per second (unit: Hz)
constexpr float kGravity = 9.81f;   // the jump's flight is ballistic (unit: m/s^2)

float standing_hips() { return bind_positions()[kHips].y(); }

// Where a foot joint (ankle or toes) is when he stands: its bind position, moved out to
// kStanceTrack from the midline.
Vec3 standing(Joint foot_joint) {
  const Vec3 bind = bind_positions()[foot_joint];
  return Vec3(is_left(foot_joint) ? kStanceTrack : -kStanceTrack, bind.y(), bind.z());
}

// The trunk bent forward by `lean` (unit: rad), shared over the spine, head kept level.
void lean_trunk(MarinePose& p, float lean, float yaw = 0.0f) {
  p.world[kSpine] = about_y(0.3f * yaw) * about_x(0.4f * lean);
  p.world[kSpine1] = about_y(0.6f * yaw) * about_x(0.75f * lean);
  p.world[kSpine2] = about_y(yaw) * about_x(lean);
  p.world[kNeck] = about_y(yaw) * about_x(0.5f * lean);
  p.world[kHead] = about_y(yaw) * about_x(0.15f * lean);
}

// A foot planted flat where it stands, or rolled onto its ball (pitch < 0: heel up).
void plant(MarinePose& p, bool left, float pitch) {
  const Vec3 toes = standing(left ? kLeftToeBase : kRightToeBase);
  p.place_leg(left, ankle_from_toe_joint(toes, pitch), foot_pitch(pitch), Quat::Identity(), Vec3::UnitZ());
}

int key_count(float duration) { return static_cast<int>(std::lround(duration * kKeyRate)); }

// Standing at ease: two breaths in its 4 s, the weight shifting from foot to foot and back
// once, the head looking a little about. Feet planted: nothing slides.
Clip make_idle(const Skeleton& skeleton) {
  constexpr float kDuration = 4.0f;
  const int n = key_count(kDuration);
  Clip clip = empty_clip(skeleton, kIdleClip, kDuration, true);
  for (int i = 0; i < n; ++i) {
    const float t = kDuration * static_cast<float>(i) / static_cast<float>(n);
    const float shift = std::sin(2.0f * kPi * t / kDuration);
    const float breath = std::sin(2.0f * kPi * 2.0f * t / kDuration);
    MarinePose p = MarinePose::bind();
    p.hips = Vec3(0.018f * shift, standing_hips() - 0.015f - 0.004f * breath, 0.0f);
    p.world[kHips] = about_z(0.03f * shift);  // the hip over the loaded leg rises
    lean_trunk(p, 0.02f - 0.012f * breath, 0.05f * std::sin(2.0f * kPi * t / kDuration + 1.0f));
    p.world[kSpine] = about_z(-0.02f * shift) * p.world[kSpine];  // the trunk stays upright over it
    plant(p, true, 0.0f);
    plant(p, false, 0.0f);
    for (int side = 0; side < 2; ++side) {
      const float s = side == 0 ? 1.0f : -1.0f;
      p.place_arm(side == 0, 0.05f + 0.015f * breath, kArmClearance + 0.02f * (1.0f + s * shift), 0.25f);
    }
    p.key(clip, t);
  }
  return clip;
}

// A standing jump: crouch with the arms back, push off onto the toes with the arms swinging
// up, a ballistic flight of kFlight s with the legs tucking a little, land on the balls of the
// feet and sink to absorb it, stand up again. Not looping.
Clip make_jump(const Skeleton& skeleton) {
  constexpr float kCrouch = 0.10f, kLow = 0.42f, kTakeOff = 0.62f, kFlight = 0.50f;
  constexpr float kLand = kTakeOff + kFlight, kAbsorbed = kLand + 0.18f, kDuration = kLand + 0.55f;
  constexpr float kDepth = 0.24f;     // crouch (unit: m)
  constexpr float kToePoint = 0.55f;  // heel up at take-off and landing (unit: rad)
  const float stand = standing_hips();
  const float take_off_height = stand + 0.05f;
  const float v0 = 0.5f * kGravity * kFlight;  // up at take-off, down at landing (unit: m/s)
  auto hermite = [](float p0, float m0, float p1, float m1, float u, float h) {
    const float u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * h * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * h * m1;
  };
  auto hips_height = [&](float t) {
    if (t < kCrouch) return stand;
    if (t < kLow) return hermite(stand, 0.0f, stand - kDepth, 0.0f, (t - kCrouch) / (kLow - kCrouch), kLow - kCrouch);
    if (t < kTakeOff) return hermite(stand - kDepth, 0.0f, take_off_height, v0, (t - kLow) / (kTakeOff - kLow), kTakeOff - kLow);
    if (t < kLand) {
      const float s = t - kTakeOff;
      return take_off_height + v0 * s - 0.5f * kGravity * s * s;
    }
    if (t < kAbsorbed)
      return hermite(take_off_height, -v0, stand - 0.7f * kDepth, 0.0f, (t - kLand) / (kAbsorbed - kLand), kAbsorbed - kLand);
    return hermite(stand - 0.7f * kDepth, 0.0f, stand, 0.0f, std::min(1.0f, (t - kAbsorbed) / (kDuration - kAbsorbed)),
                   kDuration - kAbsorbed);
  };
  const KeyCurve heel{{kLow, 0.0f}, {kTakeOff, -kToePoint}, {kLand, -kToePoint}, {kAbsorbed, 0.0f}};
  const KeyCurve lean{{0.0f, 0.03f}, {kLow, 0.45f}, {kTakeOff, 0.05f}, {kLand, 0.12f}, {kAbsorbed, 0.35f}, {kDuration, 0.03f}};
  const KeyCurve arms{{0.0f, 0.05f}, {kLow, -0.9f}, {kTakeOff + 0.08f, 2.0f}, {kLand, 1.0f}, {kAbsorbed, 0.4f}, {kDuration, 0.05f}};
  const KeyCurve tuck{{kTakeOff, 0.0f}, {kTakeOff + 0.5f * kFlight, 0.12f}, {kLand, 0.0f}};
  const int n = key_count(kDuration);
  Clip clip = empty_clip(skeleton, kJumpClip, kDuration, false);
  for (int i = 0; i <= n; ++i) {
    const float t = kDuration * static_cast<float>(i) / static_cast<float>(n);
    MarinePose p = MarinePose::bind();
    p.hips.y() = hips_height(t);
    p.world[kHips] = about_x(0.5f * lean(t));
    lean_trunk(p, lean(t));
    const bool airborne = t > kTakeOff && t < kLand;
    for (int side = 0; side < 2; ++side) {
      const bool left = side == 0;
      if (!airborne) {
        plant(p, left, heel(t));
      } else {
        // In the air the feet hang from the hips as they left the ground, tucking up a little.
        Vec3 a = ankle_from_toe_joint(standing(left ? kLeftToeBase : kRightToeBase), -kToePoint);
        a.y() += p.hips.y() - take_off_height + tuck(t);
        p.place_leg(left, a, foot_pitch(-kToePoint), Quat::Identity(), Vec3::UnitZ());
      }
      p.place_arm(left, arms(t), kArmClearance, 0.3f + 0.3f * std::max(0.0f, -arms(t)));
    }
    p.key(clip, t);
  }
  return clip;
}

// A kick with the right foot: the weight moves onto the left, the right leg draws back with the
// knee bent, swings through fast (the foot passes through about 7 m/s low in front) and
// follows through high, then steps back down where it stood. The left foot stays planted.
Clip make_kick(const Skeleton& skeleton) {
  constexpr float kDuration = 1.3f;
  const Vec3 stand = standing(kRightFoot);
  const float x = stand.x();
  // The right ankle's path (unit: m, s) and the foot's pitch along it.
  const KeyCurve ax{{0.0f, x}, {0.25f, x + 0.01f}, {0.62f, x + 0.03f}, {0.9f, x + 0.02f}, {1.15f, x}};
  const KeyCurve ay{{0.0f, stand.y()}, {0.2f, stand.y() + 0.03f}, {0.45f, 0.42f}, {0.53f, 0.2f},
                    {0.62f, 0.45f}, {0.75f, 0.6f}, {1.0f, 0.2f}, {1.15f, stand.y()}};
  const KeyCurve az{{0.0f, stand.z()}, {0.2f, stand.z() - 0.05f}, {0.45f, -0.36f}, {0.53f, 0.05f},
                    {0.62f, 0.5f}, {0.75f, 0.55f}, {1.0f, 0.1f}, {1.15f, stand.z()}};
  const KeyCurve pitch{{0.0f, 0.0f}, {0.2f, -0.2f}, {0.45f, -0.9f}, {0.53f, -0.5f}, {0.62f, -0.3f},
                       {0.75f, 0.0f}, {1.0f, 0.05f}, {1.15f, 0.0f}};
  const KeyCurve shift{{0.0f, 0.0f}, {0.25f, 0.07f}, {0.95f, 0.07f}, {1.2f, 0.0f}};  // hips over the left foot
  const KeyCurve lean{{0.0f, 0.03f}, {0.45f, 0.15f}, {0.62f, -0.12f}, {0.8f, -0.08f}, {kDuration, 0.03f}};
  const KeyCurve twist{{0.0f, 0.0f}, {0.45f, -0.25f}, {0.62f, 0.2f}, {0.85f, 0.1f}, {kDuration, 0.0f}};
  const KeyCurve drop{{0.0f, 0.0f}, {0.3f, 0.04f}, {1.0f, 0.04f}, {kDuration, 0.0f}};
  const int n = key_count(kDuration);
  Clip clip = empty_clip(skeleton, kKickClip, kDuration, false);
  for (int i = 0; i <= n; ++i) {
    const float t = kDuration * static_cast<float>(i) / static_cast<float>(n);
    MarinePose p = MarinePose::bind();
    p.hips = Vec3(shift(t), standing_hips() - drop(t), 0.0f);
    p.world[kHips] = about_y(twist(t)) * about_z(0.6f * shift(t)) * about_x(0.5f * lean(t));
    lean_trunk(p, lean(t), -0.5f * twist(t));
    plant(p, true, 0.0f);
    p.place_leg(false, Vec3(ax(t), ay(t), az(t)), foot_pitch(pitch(t)), Quat::Identity(), Vec3::UnitZ());
    // Arms out for balance, the left one forward as the right leg swings through.
    p.place_arm(true, 0.3f + 1.2f * twist(t), 0.5f, 0.5f);
    p.place_arm(false, 0.1f - 1.0f * twist(t), 0.45f, 0.5f);
    p.key(clip, t);
  }
  return clip;
}

}  // namespace

std::vector<Clip> make_clips(const Skeleton& skeleton) {
  std::vector<Clip> clips;
  clips.push_back(make_idle(skeleton));
  clips.push_back(make_gait_clip(skeleton, walk_design()));
  clips.push_back(make_gait_clip(skeleton, run_design()));
  clips.push_back(make_jump(skeleton));
  clips.push_back(make_kick(skeleton));
  return clips;
}

}  // namespace ballpit::marine
