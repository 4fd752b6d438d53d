#include "systems/clip_sampling.h"

#include <algorithm>
#include <cmath>

#include "engine/error.h"

namespace ballpit {

namespace {

// Keys walked from the cursor before giving up and binary-searching: one frame at any sane
// playback rate moves past at most a key or two (the Wuson's keys are 1/30 s apart).
constexpr int kMaxCursorWalk = 4;

// k with times[k] <= t < times[k + 1]; 0 if t is before the first key, n - 1 after the last.
std::uint32_t find_key(const std::vector<float>& times, float t, std::uint32_t hint) {
  const std::uint32_t n = static_cast<std::uint32_t>(times.size());
  std::uint32_t k = std::min(hint, n - 1);
  for (int walk = 0; walk < kMaxCursorWalk; ++walk) {
    if (t < times[k]) {
      if (k == 0) return 0;
      --k;
    } else if (k + 1 < n && t >= times[k + 1]) {
      ++k;
    } else {
      return k;
    }
  }
  auto it = std::upper_bound(times.begin(), times.end(), t);
  return it == times.begin() ? 0u : static_cast<std::uint32_t>(it - times.begin() - 1);
}

Vec3 lerp(const Vec3& a, const Vec3& b, float alpha) { return a + (b - a) * alpha; }

Quat slerp(const Quat& a, const Quat& b, float alpha) {
  if (alpha == 0.0f) return a;  // a key time returns the key bit for bit
  return a.slerp(alpha, b);     // Eigen takes the shorter arc
}

template <class V, class Mix>
V sample_channel(const std::vector<float>& times, const std::vector<V>& values, float t, const Clip& clip,
                 std::uint32_t& cursor, Mix mix) {
  const std::size_t n = times.size();
  if (n == 1) return values[0];
  const std::uint32_t k = find_key(times, t, cursor);
  cursor = k;
  const float first = times.front(), last = times.back();
  // The seam of a looping clip whose keys do not cover [0, duration]: last key -> first key.
  const float seam = clip.duration - (last - first);
  const bool wraps = clip.looping && seam > 0.0f;
  if (t < first) {
    if (!wraps) return values.front();
    return mix(values.back(), values.front(), (t + clip.duration - last) / seam);
  }
  if (k + 1 < n) {
    // A looping clip keyed up to its very end (X files key the last frame at the duration)
    // closes on its first key: the last interval runs into values.front(), not values.back(),
    // which may differ from it by a few degrees and would jump at every loop.
    const bool closes = clip.looping && k + 2 == n && last >= clip.duration;
    const V& next = closes ? values.front() : values[k + 1];
    return mix(values[k], next, (t - times[k]) / (times[k + 1] - times[k]));
  }
  if (!wraps) return values.back();
  return mix(values.back(), values.front(), (t - last) / seam);
}

}  // namespace

float clip_local_time(const Clip& clip, float time) {
  if (!(clip.duration > 0.0f) || !std::isfinite(time)) return 0.0f;
  if (!clip.looping) return std::clamp(time, 0.0f, clip.duration);
  float t = time - std::floor(time / clip.duration) * clip.duration;
  return (t >= clip.duration || t < 0.0f) ? 0.0f : t;  // rounding can land exactly on duration
}

void sample_clip(const Clip& clip, float time, ClipCursor& cursor, LocalPose& out) {
  const std::size_t joints = clip.tracks.size();
  if (cursor.rotation.size() != joints) cursor.reset(joints);
  out.resize(joints);
  const float t = clip_local_time(clip, time);
  for (std::size_t j = 0; j < joints; ++j) {
    const JointTrack& track = clip.tracks[j];
    out.translation[j] = sample_channel(track.translation_times, track.translations, t, clip, cursor.translation[j], lerp);
    out.rotation[j] = sample_channel(track.rotation_times, track.rotations, t, clip, cursor.rotation[j], slerp);
    out.scale[j] = sample_channel(track.scale_times, track.scales, t, clip, cursor.scale[j], lerp);
  }
}

void rest_pose(const Skeleton& skeleton, LocalPose& out) {
  out.translation = skeleton.rest_translation;
  out.rotation = skeleton.rest_rotation;
  out.scale = skeleton.rest_scale;
}

void blend_poses(std::span<const LocalPose* const> poses, std::span<const float> weights, LocalPose& out) {
  if (poses.size() != weights.size() || poses.empty()) throw Error("blend_poses: one weight per pose is required");
  float total = 0.0f;
  std::size_t active = 0, only = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    if (!(weights[i] >= 0.0f) || !std::isfinite(weights[i]))
      throw Error("blend_poses: weight " + std::to_string(i) + " must be finite and >= 0");
    if (weights[i] > 0.0f) {
      total += weights[i];
      ++active;
      only = i;
    }
  }
  if (active == 0) throw Error("blend_poses: the weights sum to 0");
  const std::size_t joints = poses[only]->size();
  if (active == 1) {
    out = *poses[only];
    return;
  }
  out.resize(joints);
  const float inv_total = 1.0f / total;
  for (std::size_t j = 0; j < joints; ++j) {
    Vec3 t = Vec3::Zero(), s = Vec3::Zero();
    Vec4 q = Vec4::Zero();
    Vec4 reference = Vec4::Zero();
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (weights[i] == 0.0f) continue;
      const LocalPose& p = *poses[i];
      const float w = weights[i] * inv_total;
      t += w * p.translation[j];
      s += w * p.scale[j];
      Vec4 c = p.rotation[j].coeffs();
      if (reference.isZero(0.0f)) reference = c;
      q += (c.dot(reference) < 0.0f ? -w : w) * c;  // q and -q are one rotation: stay on one side
    }
    out.translation[j] = t;
    out.scale[j] = s;
    out.rotation[j] = Quat(q.normalized());
  }
}

void local_to_model(const Skeleton& skeleton, const LocalPose& local, std::vector<Affine3>& model) {
  const std::size_t joints = skeleton.size();
  model.resize(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    Affine3 l;
    l.fromPositionOrientationScale(local.translation[j], local.rotation[j], local.scale[j]);
    const int parent = skeleton.parents[j];
    model[j] = parent < 0 ? l : model[static_cast<std::size_t>(parent)] * l;
  }
}

}  // namespace ballpit
