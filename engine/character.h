// Characters: rigged, skinned models walked through the pit by a controller. A character is
// an entity whose data is split by who writes it, so systems declare exactly what they touch:
//   CharacterSetup  - fixed at spawn (model, clips, gaits, scale, fitted collider shapes): no
//                     system writes it, every character system may read it;
//   CharacterMotion - ColumnId::CharacterController: input, script, and the root at the start
//                     and end of the coming step (written by the controller);
//   CharacterPose   - ColumnId::CharacterPose: locomotion phase, blend weights, key cursors,
//                     joint transforms at both ends of the step, skinning palettes, foot slip.
// Decision: the character is kinematic. Nothing the balls do moves it, gravity does not act on
// it, and its colliders have infinite mass.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/access.h"
#include "engine/entity.h"
#include "engine/math.h"
#include "engine/model.h"
#include "engine/pose.h"

namespace ballpit {

// How joint colliders are fitted: spheres at joints (the method of the report this project
// grew from) or capsules along bones (its proposed improvement, and the default).
enum class ColliderKind : std::uint8_t { Spheres, Capsules };

// Locomotion roles, indexing the per-role arrays below.
enum LocomotionRole : int { kIdle = 0, kWalk = 1, kRun = 2, kRoles = 3 };

// One-shot actions, played over the locomotion blend (systems/actions.h), indexing the
// per-action arrays below.
enum ActionRole : int { kJump = 0, kKick = 1, kActions = 2 };

// What a clip does at playback rate 1, measured from it at spawn (systems/locomotion.h).
struct Gait {
  float speed = 0.0f;      // ground speed that keeps the planted foot still (unit: m/s)
  float cycle = 0.0f;      // clip duration, one locomotion cycle (unit: s)
  float touchdown = 0.0f;  // normalised time at which the reference foot is furthest forward
  float slip = 0.0f;       // least foot slide per metre travelled at `speed`: the clip's own floor
  float slip_per_cycle = 0.0f;  // planted-foot slide over one cycle at `speed`, flights left out (unit: m)
  float flight = 0.0f;     // fraction of the cycle with no foot on the ground
};

struct ControllerInput {
  float forward = 0.0f;  // -1 (backward) .. 1 (forward)
  float turn = 0.0f;     // -1 (right) .. 1 (left), seen from above with y up
  bool run = false;
  bool jump = false;  // play the jump when no action plays (held: jump again on landing)
  bool kick = false;  // play the kick likewise
};

// A scripted input: `input` is held for `duration` (unit: s), then the next segment starts.
struct ScriptSegment {
  float duration = 0.0f;
  ControllerInput input;
};

struct ControllerSettings {
  float walk_speed = 0.0f;     // full forward input, walking; 0: the walk clip's gait speed (unit: m/s)
  float run_speed = 0.0f;      // full forward input, running; 0: the run clip's gait speed (unit: m/s)
  float back_speed = 0.0f;     // full backward input; 0: the walk speed (unit: m/s)
  float turn_rate = 1.5708f;   // yaw rate at full turn input, 90 degrees a second (unit: rad/s)
  float acceleration = 3.0f;   // how fast ground speed follows the input (unit: m/s^2)
  // Least time for a full change of blend weights (idle -> walk, walk -> run) (unit: s). It caps
  // the acceleration where the gaits lie close together: 3 m/s^2 alone would take the Wuson to
  // its 0.48 m/s walk in 10 frames, swinging its tail from the idle (bind) pose to the walk
  // pose, a metre away, at 6 m/s.
  float blend_time = 0.4f;
  float wall_clearance = 0.1f; // gap kept between the footprint circle and the walls (unit: m)
};

// The character's root: the floor point under its pivot, its heading and its ground speed.
struct RootState {
  Vec3 position = Vec3::Zero();  // (unit: m); y is the height the character stands at
  float heading = 0.0f;          // yaw about +y from the model's forward axis (unit: rad)
  float speed = 0.0f;            // signed ground speed along the heading (unit: m/s)
};

// One fitted joint collider, in its joint's bind space (model units): a segment and a radius.
// A sphere has a == b.
struct BoneShape {
  std::uint16_t joint = 0;
  Vec3 a = Vec3::Zero();
  Vec3 b = Vec3::Zero();
  float radius = 0.0f;
};

struct CharacterSetup {
  Entity entity;
  std::shared_ptr<const Model> model;
  std::array<std::uint32_t, kRoles> clips{};  // clip index playing each role
  std::array<Gait, kRoles> gaits{};           // idle's is all zero
  std::array<std::int32_t, kActions> actions{-1, -1};  // clip index of each action, -1: none
  float scale = 1.0f;                         // model units -> m
  Vec3 pivot = Vec3::Zero();                  // model point placed at the root (model units)
  Vec3 forward = Vec3::UnitZ();               // the model's facing axis (model space, unit)
  std::vector<std::uint16_t> feet;            // foot joints, for gait and foot slip
  ControllerSettings controller;              // speeds resolved at spawn (never 0)
  float footprint_radius = 0.0f;  // horizontal reach of any collider from the root, any clip (unit: m)
  float lowest_collider = 0.0f;   // lowest collider surface below the root, any clip (unit: m, < 0)
  ColliderKind collider_kind = ColliderKind::Capsules;
  std::vector<BoneShape> shapes;  // one per collider row
  std::uint32_t first_collider = 0;  // rows [first_collider, first_collider + shapes.size())
};

struct CharacterMotion {
  ControllerInput input;              // what a player or the app asks for
  std::vector<ScriptSegment> script;  // when not empty, replaces `input` while it runs
  float script_time = 0.0f;           // time into the script (unit: s)
  RootState previous;                 // root at the start of the coming step
  RootState current;                  // root at its end
};

// Foot slip, sampled each step while the character moves: the horizontal world speed of the
// planted foot, the foot that moves least over the ground that step. The lowest foot's speed is
// kept beside it: it is the textbook definition, but for a model whose feet tip in the swing
// (the Wuson) the lowest foot is often the swinging one.
struct FootSlip {
  double sum = 0.0;         // sum of planted-foot slip speeds (unit: m/s)
  double lowest_sum = 0.0;  // sum of lowest-foot speeds (unit: m/s)
  double ground_sum = 0.0;  // sum of |ground speed| over the same steps (unit: m/s)
  float max = 0.0f;         // largest planted-foot slip (unit: m/s)
  std::uint64_t samples = 0;
  double mean() const { return samples ? sum / static_cast<double>(samples) : 0.0; }
  double lowest_mean() const { return samples ? lowest_sum / static_cast<double>(samples) : 0.0; }
  // Mean planted-foot slip as a fraction of mean ground speed: 0 is no sliding at all.
  double fraction() const { return ground_sum > 0.0 ? sum / ground_sum : 0.0; }
};

struct CharacterPose {
  float phase = 0.0f;                       // shared normalised locomotion cycle, [0, 1)
  float idle_time = 0.0f;                   // the idle clip's own clock (unit: s)
  std::array<float, kRoles> weights{1.0f, 0.0f, 0.0f};
  std::array<ClipCursor, kRoles> cursors;
  std::array<LocalPose, kRoles> samples;    // scratch: each role's sampled pose
  std::int32_t action = -1;                 // the ActionRole playing, -1: none
  float action_time = 0.0f;                 // time into its clip (unit: s)
  ClipCursor action_cursor;
  LocalPose action_sample;                  // scratch: the action's sampled pose
  LocalPose locomotion;                     // scratch: the locomotion blend under an action
  LocalPose local;                          // the blended pose
  std::vector<Affine3> model_previous;      // joint model transforms at the start of the step
  std::vector<Affine3> model;               // and at its end
  std::vector<std::vector<Mat4>> palettes;  // per mesh: world-space skinning matrices, end of step
  FootSlip slip;
};

// The character's world transform: root translation and yaw, uniform scale, pivot at origin.
Affine3 character_transform(const CharacterSetup& setup, const RootState& root);

class CharacterTable {
 public:
  std::size_t size() const { return setup_.size(); }
  std::uint32_t add(CharacterSetup setup, CharacterMotion motion, CharacterPose pose);
  void clear();
  // Row of a character entity, or -1.
  int find(Entity e) const;

  // Fixed at spawn: readable by anyone, no column to declare.
  const CharacterSetup& setup(std::size_t i) const { return setup_[i]; }
  const CharacterMotion& motion(std::size_t i) const {
    check_access(ColumnId::CharacterController, false);
    return motion_[i];
  }
  CharacterMotion& mut_motion(std::size_t i) {
    check_access(ColumnId::CharacterController, true);
    return motion_[i];
  }
  const CharacterPose& pose(std::size_t i) const {
    check_access(ColumnId::CharacterPose, false);
    return pose_[i];
  }
  CharacterPose& mut_pose(std::size_t i) {
    check_access(ColumnId::CharacterPose, true);
    return pose_[i];
  }

 private:
  std::vector<CharacterSetup> setup_;
  std::vector<CharacterMotion> motion_;
  std::vector<CharacterPose> pose_;
};

}  // namespace ballpit
