// Walk and run cycles for the marine, made from where his feet must be: each planted foot is
// held on the ground (it moves back at exactly the gait speed, in place), rolling from heel to
// flat to ball; each swinging foot travels from toe-off to the next heel strike on a smooth
// path; the legs reach both by IK from hips that bob, sway, tilt and turn as in human gait,
// with the arms swinging against the legs.
// Decision: joint angles are an outcome, not an input. Prescribing hip and knee curves from
// gait tables and hoping the feet stay put leaves them sliding (the Wuson slides 25%); placing
// the feet and solving the legs keeps the planted foot still to the keys' precision, and the
// hip, knee and ankle curves come out in the ranges the tables give (tests/test_marine_gait.cpp).
#pragma once

#include "engine/clip.h"
#include "engine/marine/marine_pose.h"
#include "engine/skeleton.h"

namespace ballpit::marine {

// One gait's shape. Angles in rad, lengths in m, times as fractions of the cycle or the stance.
struct GaitDesign {
  const char* name = "walk";
  float speed = 1.4f;             // ground speed the cycle is made for (unit: m/s)
  float cycle = 1.1f;             // two steps (unit: s)
  float stance = 0.62f;           // fraction of the cycle each foot is on the ground (< 0.5: flight)
  float heel_strike_pitch = 0.25f;  // toes up as the heel strikes
  float foot_flat = 0.15f;        // fraction of the stance at which the sole is flat
  float heel_off = 0.42f;         // fraction of the stance at which the heel rises
  float toe_off_pitch = 0.8f;     // heel up (toes down) as the toes leave the ground
  float mid_stance_ankle = -0.10f; // ankle ahead of the hip joint at mid-stance
  float clearance = 0.10f;        // extra ankle lift in mid-swing
  float track = kStanceTrack;     // each foot's distance from the midline
  float hips_drop = 0.0f;         // hips below standing height, on average
  float hips_bob = 0.0f;          // extra drop at mid-stance, none in mid-flight (running)
  float sway = 0.02f;             // hips over the stance foot
  float pelvis_yaw = 0.07f;       // pelvis turns with the swinging leg
  float pelvis_roll = 0.05f;      // pelvis drops on the swing side
  float lean = 0.04f;             // trunk forward
  float arm_swing = 0.3f;         // shoulder flexion amplitude, against the legs
  float arm_abduction = kArmClearance;  // arms out from the sides
  float elbow = 0.3f;             // elbow bend at the back of the swing
  float elbow_swing = 0.2f;       // more bend at the front
};

GaitDesign walk_design();
GaitDesign run_design();

// The cycle as a looping clip keyed at about 60 Hz.
Clip make_gait_clip(const Skeleton& skeleton, const GaitDesign& design);

}  // namespace ballpit::marine
