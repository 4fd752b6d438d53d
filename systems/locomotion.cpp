#include "systems/locomotion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "systems/clip_sampling.h"

namespace ballpit {

namespace {

// Samples per cycle for gait measurement: the Wuson's keys are 1/30 s apart, so even its
// 0.97 s run gets several samples per key interval.
constexpr int kGaitSamples = 240;
// Candidate speeds per scan pass; two passes resolve the speed to (fastest foot) / 100^2.
constexpr int kGaitSpeedScan = 100;

float wrap01(float x) {
  float f = x - std::floor(x);
  return f >= 1.0f ? 0.0f : f;
}

bool has_bone_child(const Skeleton& sk, std::size_t j) {
  for (std::size_t k = j + 1; k < sk.size(); ++k)
    if (sk.parents[k] == static_cast<int>(j) && sk.is_bone[k]) return true;
  return false;
}

}  // namespace

std::vector<std::uint16_t> find_feet(const Model& model) {
  const Skeleton& sk = model.skeleton;
  LocalPose rest;
  rest_pose(sk, rest);
  std::vector<Affine3> m;
  local_to_model(sk, rest, m);
  const float limit = model.bind_min.y() + kFootHeightFraction * model.bind_height();
  std::vector<std::uint16_t> feet;
  int lowest = -1;
  for (std::size_t j = 0; j < sk.size(); ++j) {
    if (!sk.is_bone[j]) continue;
    const float y = m[j].translation().y();
    if (lowest < 0 || y < m[static_cast<std::size_t>(lowest)].translation().y()) lowest = static_cast<int>(j);
    if (!has_bone_child(sk, j) && y <= limit) feet.push_back(static_cast<std::uint16_t>(j));
  }
  if (feet.empty() && lowest >= 0) feet.push_back(static_cast<std::uint16_t>(lowest));
  return feet;
}

Gait measure_gait(const Model& model, std::size_t clip_index, std::span<const std::uint16_t> feet, float scale,
                  const Vec3& forward) {
  const Clip& clip = model.clips[clip_index];
  Gait g;
  g.cycle = clip.duration;
  if (!(clip.duration > 0.0f) || feet.empty()) return g;
  const Vec3 fwd = Vec3(forward.x(), 0.0f, forward.z()).normalized();
  const int n = kGaitSamples;
  const std::size_t nf = feet.size();
  std::vector<Vec3> foot(nf * n);  // foot f at sample i: foot[i * nf + f], scaled, model space
  ClipCursor cursor;
  cursor.reset(model.skeleton.size());
  LocalPose local;
  std::vector<Affine3> m;
  int reference_front = 0;
  for (int i = 0; i < n; ++i) {
    sample_clip(clip, clip.duration * static_cast<float>(i) / static_cast<float>(n), cursor, local);
    local_to_model(model.skeleton, local, m);
    for (std::size_t f = 0; f < nf; ++f) foot[i * nf + f] = scale * m[feet[f]].translation();
    if (foot[i * nf].dot(fwd) > foot[reference_front * nf].dot(fwd)) reference_front = i;
  }
  g.touchdown = static_cast<float>(reference_front) / static_cast<float>(n);

  // Horizontal foot velocities relative to the root, by central difference (the clip is one
  // cycle, so the ends wrap).
  const float dt = clip.duration / static_cast<float>(n);
  std::vector<Vec3> v(nf * n);
  float fastest = 0.0f;
  for (int i = 0; i < n; ++i)
    for (std::size_t f = 0; f < nf; ++f) {
      Vec3 d = (foot[((i + 1) % n) * nf + f] - foot[((i + n - 1) % n) * nf + f]) / (2.0f * dt);
      d.y() = 0.0f;
      v[i * nf + f] = d;
      fastest = std::max(fastest, d.norm());
    }
  // A sample is a flight (a run's) when no foot is within kGroundContact of the lowest it goes
  // in the cycle: nothing is planted then and nothing can slip, so it is left out. Otherwise
  // every foot may be the planted one, however high (the Wuson's hooves tip below the planted
  // ones in the swing, so height alone does not tell which foot bears the weight).
  std::vector<float> lowest(nf, std::numeric_limits<float>::max());
  for (int i = 0; i < n; ++i)
    for (std::size_t f = 0; f < nf; ++f) lowest[f] = std::min(lowest[f], foot[i * nf + f].y());
  std::vector<std::uint8_t> airborne(n, 1);
  int flight = 0;
  for (int i = 0; i < n; ++i) {
    for (std::size_t f = 0; f < nf; ++f)
      if (foot[i * nf + f].y() <= lowest[f] + kGroundContact) airborne[i] = 0;
    flight += airborne[i];
  }
  g.flight = static_cast<float>(flight) / static_cast<float>(n);

  // Moving at ground speed s, foot f slides at |v + s fwd|; the planted foot is the one that
  // slides least. Played at the rate that follows ground speed (s' / speed for any ground
  // speed s'), the clip slides by s' x slip(speed) / speed: the gait speed is the s that makes
  // slip(s) / s least over the cycle. A coarse scan of (0, fastest foot], then a fine one
  // around the best.
  auto slip = [&](float s, bool in_flight_too) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      if (airborne[i] && !in_flight_too) continue;
      float least = std::numeric_limits<float>::max();
      for (std::size_t f = 0; f < nf; ++f) least = std::min(least, (v[i * nf + f] + s * fwd).norm());
      sum += least;
    }
    return sum;
  };
  float best = 0.0f, lo = 0.0f, hi = fastest;
  double best_slip = std::numeric_limits<double>::max();
  for (int pass = 0; pass < 2; ++pass) {
    const float step = (hi - lo) / static_cast<float>(kGaitSpeedScan);
    best_slip = std::numeric_limits<double>::max();
    for (int k = 0; k <= kGaitSpeedScan; ++k) {
      const float s = lo + step * static_cast<float>(k);
      if (!(s > 0.0f)) continue;
      const double e = slip(s, false) / s;
      if (e < best_slip) {
        best_slip = e;
        best = s;
      }
    }
    lo = std::max(best - step, 0.0f);
    hi = best + step;
  }
  // A clip made in place from root motion (engine/clip_sources.h) states its speed: the travel
  // the animator matched the feet to. The feet's best speed above is an estimate of that (it
  // carries the clip's foot-slide error), so the stated speed is the gait speed, and the slip
  // is the feet's at that speed: a travel the feet do not follow fails the cycle check.
  if (clip.root_speed > 0.0f) {
    best = scale * clip.root_speed;
    best_slip = slip(best, false) / best;
  }
  g.speed = best;
  if (best > 0.0f) {
    // Per metre over every sample, as the animation system measures a character's slip step by
    // step; per cycle over the planted samples only.
    g.slip = static_cast<float>(slip(best, true) / best / n);
    g.slip_per_cycle = static_cast<float>(best_slip * best * dt);
  }
  return g;
}

std::array<float, kRoles> locomotion_weights(float speed, const std::array<Gait, kRoles>& gaits) {
  const float s = std::abs(speed);
  const float walk = gaits[kWalk].speed, run = gaits[kRun].speed;
  std::array<float, kRoles> w{0.0f, 0.0f, 0.0f};
  if (!(s > 0.0f)) {
    w[kIdle] = 1.0f;
  } else if (s < walk) {
    w[kWalk] = s / walk;
    w[kIdle] = 1.0f - w[kWalk];
  } else if (s < run) {
    w[kRun] = (s - walk) / (run - walk);
    w[kWalk] = 1.0f - w[kRun];
  } else {
    w[kRun] = 1.0f;
  }
  return w;
}

float phase_rate(float speed, const std::array<float, kRoles>& w, const std::array<Gait, kRoles>& gaits) {
  const float s = std::abs(speed);
  if (!(s > 0.0f)) return 0.0f;
  float rate;
  if (w[kIdle] > 0.0f) {
    rate = 1.0f / gaits[kWalk].cycle;
  } else {
    const float stride = w[kWalk] * gaits[kWalk].speed * gaits[kWalk].cycle + w[kRun] * gaits[kRun].speed * gaits[kRun].cycle;
    rate = s / stride;
  }
  return speed < 0.0f ? -rate : rate;
}

float role_clip_time(const Gait& gait, float phase) { return wrap01(phase + gait.touchdown) * gait.cycle; }

}  // namespace ballpit
