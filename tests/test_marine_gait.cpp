// The marine's clips as gait: walk and run at their own speeds plant each foot without sliding
// (under 2 cm a step, the engine's own gait measure), alternate the feet half a cycle apart,
// the run flies and the walk does not, and the hip, knee and ankle swing through the ranges of
// human gait data. Built from the skeleton and clips alone: the body plays no part in gait.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/marine/marine.h"
#include "engine/marine/marine_clips.h"
#include "engine/marine/marine_skeleton.h"
#include "systems/clip_sampling.h"
#include "systems/locomotion.h"

namespace ballpit {
namespace {

using namespace marine;

const Model& gait_model() {
  static const Model m = [] {
    Model model;
    model.path = "the marine's skeleton and clips";
    model.skeleton = make_skeleton();
    model.clips = make_clips(model.skeleton);
    model.bind_min = Vec3(-0.5f, 0.0f, -0.2f);
    model.bind_max = Vec3(0.5f, kStature, 0.3f);
    return model;
  }();
  return m;
}

float degrees(float rad) { return rad * 180.0f / std::numbers::pi_v<float>; }

struct Curves {
  std::vector<float> knee, hip, ankle;  // left leg: flexion (deg), hip flexion vs vertical, ankle dorsiflexion
  std::vector<float> toe_y[2];          // foot joint heights (m)
};

Curves sample(const Clip& clip, int n) {
  const Model& m = gait_model();
  ClipCursor cursor;
  cursor.reset(m.skeleton.size());
  LocalPose local;
  std::vector<Affine3> x;
  Curves c;
  for (int i = 0; i < n; ++i) {
    sample_clip(clip, clip.duration * static_cast<float>(i) / static_cast<float>(n), cursor, local);
    local_to_model(m.skeleton, local, x);
    const Vec3 hip = x[kLeftUpLeg].translation(), knee = x[kLeftLeg].translation();
    const Vec3 ankle = x[kLeftFoot].translation(), toe = x[kLeftToeBase].translation();
    const Vec3 thigh = (knee - hip).normalized(), shin = (ankle - knee).normalized(), foot = (toe - ankle).normalized();
    c.knee.push_back(degrees(std::acos(std::clamp(thigh.dot(shin), -1.0f, 1.0f))));
    c.hip.push_back(degrees(std::atan2(thigh.z(), -thigh.y())));  // thigh forward of vertical
    // Ankle: the angle between shin and foot past the bind pose's (dorsiflexion positive).
    const Vec3 bind_shin = (bind_positions()[kLeftFoot] - bind_positions()[kLeftLeg]).normalized();
    const Vec3 bind_foot = (bind_positions()[kLeftToeBase] - bind_positions()[kLeftFoot]).normalized();
    c.ankle.push_back(degrees(std::acos(bind_shin.dot(bind_foot)) - std::acos(std::clamp(shin.dot(foot), -1.0f, 1.0f))));
    c.toe_y[0].push_back(x[kLeftToeBase].translation().y());
    c.toe_y[1].push_back(x[kRightToeBase].translation().y());
  }
  return c;
}


// Fraction of the cycle where foot f's first ground contact lies (its touchdown).
float touchdown(const std::vector<float>& y) {
  const float low = *std::min_element(y.begin(), y.end());
  const int n = static_cast<int>(y.size());
  for (int i = 0; i < n; ++i) {
    const bool down = y[i] <= low + kGroundContact, before = y[(i + n - 1) % n] <= low + kGroundContact;
    if (down && !before) return static_cast<float>(i) / static_cast<float>(n);
  }
  return -1.0f;
}

Gait gait_of(const char* name) {
  const Model& m = gait_model();
  const auto feet = find_feet(m);
  return measure_gait(m, m.clip_index(name), feet, 1.0f, Vec3::UnitZ());
}

TEST(MarineGait, TheFeetAreTheBallsOfTheFeet) {
  const auto feet = find_feet(gait_model());
  ASSERT_EQ(feet.size(), 2u);
  EXPECT_EQ(feet[0], kLeftToeBase);
  EXPECT_EQ(feet[1], kRightToeBase);
}

TEST(MarineGait, WalkAndRunHaveTheirSpeedsAndCadence) {
  const Gait walk = gait_of(kWalkClip), run = gait_of(kRunClip);
  std::printf("walk: %.3f m/s, cycle %.3f s, slip %.4f m/step, flight %.3f\n", walk.speed, walk.cycle,
              0.5 * walk.slip_per_cycle, walk.flight);
  std::printf("run: %.3f m/s, cycle %.3f s, slip %.4f m/step, flight %.3f\n", run.speed, run.cycle,
              0.5 * run.slip_per_cycle, run.flight);
  // The figures: walk about 1.4 m/s at about 1.8 steps a second, run about 3.5 m/s.
  EXPECT_NEAR(walk.speed, 1.4f, 0.07f);
  EXPECT_NEAR(2.0f / walk.cycle, 1.8f, 0.1f);
  EXPECT_NEAR(run.speed, 3.5f, 0.175f);
}

TEST(MarineGait, ThePlantedFootSlipsUnderTwoCentimetresAStep) {
  for (const char* name : {kWalkClip, kRunClip}) {
    const Gait g = gait_of(name);
    EXPECT_LT(0.5f * g.slip_per_cycle, 0.02f) << name;
  }
}

TEST(MarineGait, TheRunFliesAndTheWalkDoesNot) {
  EXPECT_EQ(gait_of(kWalkClip).flight, 0.0f);
  EXPECT_GT(gait_of(kRunClip).flight, 0.05f);
}

TEST(MarineGait, TheFeetAlternateHalfACycleApart) {
  for (const char* name : {kWalkClip, kRunClip}) {
    const Curves c = sample(gait_model().clips[gait_model().clip_index(name)], 240);
    const float left = touchdown(c.toe_y[0]), right = touchdown(c.toe_y[1]);
    ASSERT_GE(left, 0.0f) << name;
    ASSERT_GE(right, 0.0f) << name;
    float apart = std::abs(left - right);
    EXPECT_NEAR(apart, 0.5f, 0.02f) << name;
  }
}

float lowest(const std::vector<float>& v) { return *std::min_element(v.begin(), v.end()); }
float highest(const std::vector<float>& v) { return *std::max_element(v.begin(), v.end()); }

// Sagittal angles over the cycle, against the ranges of human gait data (Winter, "Biomechanics
// and Motor Control of Human Movement", walking at natural cadence; Novacheck, "The
// biomechanics of running", 1998), widened by about 10 degrees for his build and for angles
// measured between segments in model space (hip: the thigh against the vertical, so the trunk's
// lean is not in it). Measured at the head: walk knee 6.6..68.7, hip -32..40, ankle -26..9;
// run knee 6.5..110.2, hip -10..61, ankle -32..26 degrees.
TEST(MarineGait, JointAnglesFollowHumanGaitData) {
  const Model& m = gait_model();
  const Curves walk = sample(m.clips[m.clip_index(kWalkClip)], 240);
  EXPECT_LT(lowest(walk.knee), 12.0f);             // near straight at heel strike and mid-stance
  EXPECT_NEAR(highest(walk.knee), 65.0f, 10.0f);   // about 60-65 in early swing
  EXPECT_NEAR(highest(walk.hip), 32.0f, 12.0f);    // about 30 flexion before heel strike
  EXPECT_NEAR(lowest(walk.hip), -20.0f, 15.0f);    // about 10-20 extension at toe-off
  EXPECT_NEAR(lowest(walk.ankle), -20.0f, 10.0f);  // plantarflexion at toe-off
  EXPECT_NEAR(highest(walk.ankle), 10.0f, 8.0f);   // dorsiflexion late in stance
  const Curves run = sample(m.clips[m.clip_index(kRunClip)], 240);
  EXPECT_NEAR(highest(run.knee), 110.0f, 20.0f);   // 90-130 in swing
  EXPECT_NEAR(highest(run.hip), 55.0f, 15.0f);
  EXPECT_NEAR(lowest(run.ankle), -25.0f, 10.0f);
}

}  // namespace
}  // namespace ballpit
