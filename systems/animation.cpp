#include "systems/animation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/world.h"
#include "systems/clip_sampling.h"
#include "systems/locomotion.h"

namespace ballpit {

namespace {

float smoothstep(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x * x * (3.0f - 2.0f * x);
}

void pose_skeleton(const CharacterSetup& setup, float speed, CharacterPose& pose) {
  const Model& model = *setup.model;
  pose.weights = locomotion_weights(speed, setup.gaits);
  const LocalPose* inputs[kRoles];
  for (int role = 0; role < kRoles; ++role) {
    inputs[role] = &pose.samples[role];
    if (pose.weights[role] == 0.0f) continue;  // not read by the blend: skip the sampling
    const Clip& clip = model.clips[setup.clips[role]];
    const float t = role == kIdle ? pose.idle_time : role_clip_time(setup.gaits[role], pose.phase);
    sample_clip(clip, t, pose.cursors[role], pose.samples[role]);
  }
  if (pose.action < 0) {
    blend_poses(inputs, pose.weights, pose.local);
  } else {
    blend_poses(inputs, pose.weights, pose.locomotion);
    const Clip& clip = model.clips[static_cast<std::size_t>(setup.actions[static_cast<std::size_t>(pose.action)])];
    sample_clip(clip, pose.action_time, pose.action_cursor, pose.action_sample);
    const float w = action_weight(pose.action_time, clip.duration);
    const LocalPose* layers[2] = {&pose.locomotion, &pose.action_sample};
    const float layer_weights[2] = {1.0f - w, w};
    if (w >= 1.0f) {
      pose.local = pose.action_sample;
    } else if (w <= 0.0f) {
      pose.local = pose.locomotion;
    } else {
      blend_poses(layers, layer_weights, pose.local);
    }
  }
  local_to_model(model.skeleton, pose.local, pose.model);
}

// Ends an action whose clip has played out, then starts the one the input asks for, if none
// plays and the model has it.
void advance_action(const CharacterSetup& setup, const ControllerInput& input, CharacterPose& pose, float dt) {
  const Model& model = *setup.model;
  if (pose.action >= 0) {
    pose.action_time += dt;
    const Clip& clip = model.clips[static_cast<std::size_t>(setup.actions[static_cast<std::size_t>(pose.action)])];
    if (pose.action_time >= clip.duration) pose.action = -1;
  }
  if (pose.action >= 0) return;
  const int wanted = input.jump ? kJump : input.kick ? kKick : -1;
  if (wanted < 0 || setup.actions[static_cast<std::size_t>(wanted)] < 0) return;
  pose.action = wanted;
  pose.action_time = 0.0f;
  pose.action_cursor.reset(model.skeleton.size());
}

}  // namespace

float action_weight(float time, float duration) {
  return std::min(smoothstep(time / kActionFade), smoothstep((duration - time) / kActionFade));
}

void reset_pose(const CharacterSetup& setup, const CharacterMotion& motion, CharacterPose& pose) {
  for (int role = 0; role < kRoles; ++role) pose.cursors[role].reset(setup.model->skeleton.size());
  pose.action_cursor.reset(setup.model->skeleton.size());
  pose_skeleton(setup, motion.current.speed, pose);
  pose.model_previous = pose.model;
}

void advance_pose(const CharacterSetup& setup, const CharacterMotion& motion, CharacterPose& pose, float dt) {
  pose.model_previous.swap(pose.model);
  // The mean ground speed over the step sets how far the phase moves: the ground covered.
  const float mean_speed = 0.5f * (motion.previous.speed + motion.current.speed);
  const auto mean_weights = locomotion_weights(mean_speed, setup.gaits);
  pose.phase += phase_rate(mean_speed, mean_weights, setup.gaits) * dt;
  pose.phase -= std::floor(pose.phase);
  if (pose.phase >= 1.0f) pose.phase = 0.0f;
  // The idle clip keeps its own clock, wrapped so it never grows past float precision.
  const float idle_length = setup.model->clips[setup.clips[kIdle]].duration;
  pose.idle_time = idle_length > 0.0f ? std::fmod(pose.idle_time + dt, idle_length) : 0.0f;
  advance_action(setup, motion.input, pose, dt);
  pose_skeleton(setup, motion.current.speed, pose);

  // Foot slip over the step: the planted foot moves least over the ground; the lowest foot
  // (at the end of the step) is tracked beside it. An action's feet do not walk: not counted.
  if (setup.feet.empty() || std::abs(mean_speed) < kSlipMinSpeed || pose.action >= 0) return;
  const Affine3 w0 = character_transform(setup, motion.previous);
  const Affine3 w1 = character_transform(setup, motion.current);
  float least = std::numeric_limits<float>::max(), lowest_y = least, lowest_slip = 0.0f;
  for (std::uint16_t f : setup.feet) {
    const Vec3 end = w1 * pose.model[f].translation();
    Vec3 moved = end - w0 * pose.model_previous[f].translation();
    moved.y() = 0.0f;
    const float slip = moved.norm() / dt;
    least = std::min(least, slip);
    if (end.y() < lowest_y) {
      lowest_y = end.y();
      lowest_slip = slip;
    }
  }
  pose.slip.sum += least;
  pose.slip.lowest_sum += lowest_slip;
  pose.slip.ground_sum += std::abs(mean_speed);
  pose.slip.max = std::max(pose.slip.max, least);
  ++pose.slip.samples;
}

Access AnimationSystem::access() const {
  Access a;
  a.reads = {ColumnId::CharacterController};
  a.writes = {ColumnId::CharacterPose};
  return a;
}

void AnimationSystem::run(World& world) {
  CharacterTable& characters = world.characters;
  for (std::size_t i = 0; i < characters.size(); ++i)
    advance_pose(characters.setup(i), characters.motion(i), characters.mut_pose(i), world.step());
}

}  // namespace ballpit
