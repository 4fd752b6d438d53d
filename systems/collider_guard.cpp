#include "systems/collider_guard.h"

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace ballpit {

namespace {

// Sweeps of the guard per sphere. A sphere wedged between two limbs is pushed out of each in
// turn; a few rounds settle such a wedge (one does not: the second push can undo the first).
constexpr int kGuardPasses = 4;

// Depth (fraction of the sphere's radius) below which a sphere counts as on a surface, not in
// it: one pushed exactly onto a capsule reads a gap of float rounding, about 1e-7 m in the pit.
constexpr float kSurfaceSlack = 1e-4f;

// Moves of a pinched sphere out of its pinch (squeeze_out): each clears both surfaces to first
// order, and the next corrects for their curvature. A move is at most kSqueezeReach radii: nearly
// parallel surfaces ask for a move as long as 1 / (1 - (n0 . n1)^2), metres for a ball between
// two limbs that lie side by side, where the first-order picture no longer holds. A pinch too
// long to leave within kSqueezeSteps moves is left for the next step to continue.
constexpr int kSqueezeSteps = 4;
constexpr float kSqueezeReach = 2.0f;

// Bisection steps that place a sphere where its path entered a capsule: 2^-24 of a step's path,
// below float precision of any position in the pit.
constexpr int kEntrySteps = 24;

// A collider over the step: its pose at the start and at dt, its end velocities, and a box
// around both poses grown by its radius.
struct Capsule {
  Vec3 a0, b0, a1, b1, va, vb;
  float radius;
  Vec3 lo, hi;

  Vec3 surface_velocity(float t) const { return (1.0f - t) * va + t * vb; }
};

std::vector<Capsule> capsules_of(const ColliderTable& c, float dt) {
  std::vector<Capsule> out(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) {
    Capsule& s = out[k];
    s.a0 = c.a()[k];
    s.b0 = c.b()[k];
    s.va = c.velocity_a()[k];
    s.vb = c.velocity_b()[k];
    s.a1 = s.a0 + dt * s.va;
    s.b1 = s.b0 + dt * s.vb;
    s.radius = c.radius()[k];
    const Vec3 grow = Vec3::Constant(s.radius);
    s.lo = s.a0.cwiseMin(s.b0).cwiseMin(s.a1.cwiseMin(s.b1)) - grow;
    s.hi = s.a0.cwiseMax(s.b0).cwiseMax(s.a1.cwiseMax(s.b1)) + grow;
  }
  return out;
}

// A sphere centre x against a capsule at its end pose, grown by the sphere's radius r: the
// outward normal, the gap (negative inside) and the collider's surface velocity there.
struct Frame {
  Vec3 n;
  float gap;
  Vec3 surface_velocity;
};

Frame frame_at(const Capsule& c, const Vec3& x, float r) {
  const float t = closest_segment_parameter(c.a1, c.b1, x);
  const Vec3 d = x - (c.a1 + t * (c.b1 - c.a1));
  const float dist = d.norm();
  return {dist > 1e-9f ? Vec3(d / dist) : Vec3(0.0f, 1.0f, 0.0f), dist - r - c.radius, c.surface_velocity(t)};
}

bool inside(const Frame& f, float r) { return f.gap < -kSurfaceSlack * r; }

// Moves x by `shift` and removes v's approach to the surface (relative to the surface's motion).
void put_back(Quad& x, Quad& v, const Vec3& shift, const Frame& f) {
  x = {x.x + shift.x(), x.y + shift.y(), x.z + shift.z(), x.w};
  const Vec3 vel(v.x, v.y, v.z);
  const float approach = (vel - f.surface_velocity).dot(f.n);
  if (approach < 0.0f) {
    const Vec3 kept = vel - approach * f.n;
    v = {kept.x(), kept.y(), kept.z(), v.w};
  }
}

// Where a sphere whose path from p0 (outside) crossed to the far side of the capsule's axis
// entered it; false if the path never came within reach (it went past an end).
bool entry_point(const Capsule& c, const Vec3& p0, const Vec3& p1, float reach, Vec3& entry) {
  const SegmentParameters closest = closest_segment_parameters(p0, p1, c.a1, c.b1);
  const Vec3 deepest = p0 + closest.s * (p1 - p0);
  if ((deepest - (c.a1 + closest.t * (c.b1 - c.a1))).norm() >= reach) return false;
  // The distance to the axis is convex along the path, so it crosses `reach` once before the
  // path's deepest point.
  float out = 0.0f, in = closest.s;
  for (int k = 0; k < kEntrySteps; ++k) {
    const float mid = 0.5f * (out + in);
    const Vec3 p = p0 + mid * (p1 - p0);
    const Vec3 axis = c.a1 + closest_segment_parameter(c.a1, c.b1, p) * (c.b1 - c.a1);
    ((p - axis).norm() < reach ? in : out) = mid;
  }
  entry = p0 + out * (p1 - p0);
  return true;
}

// A sphere still inside after the passes is pinched: two colliders closing on it from nearly
// opposite sides push it back and forth, each push undoing most of the other (two limbs in the
// 100k pit). It leaves the pinch sideways, as a squeezed ball does, by the
// shortest move that clears both surfaces to first order: out of the deepest collider alone if
// that does not enter another, else d = a n0 + b n1 with n_k . d = -gap_k. Nearly opposite
// normals make that move long, as it is for a ball between two close, nearly parallel limbs.
void squeeze_out(const std::vector<Capsule>& capsules, Quad& x, Quad& v) {
  const float r = x.w;
  std::vector<Frame> frames(capsules.size());
  for (int step = 0; step < kSqueezeSteps; ++step) {
    const Vec3 p(x.x, x.y, x.z);
    std::size_t deepest = 0;
    for (std::size_t k = 0; k < capsules.size(); ++k) {
      frames[k] = frame_at(capsules[k], p, r);
      if (frames[k].gap < frames[deepest].gap) deepest = k;
    }
    const Frame& f0 = frames[deepest];
    if (!inside(f0, r)) return;
    Vec3 d = -f0.gap * f0.n;
    // The collider that this move would enter deepest, to first order.
    std::size_t other = deepest;
    float entered = -kSurfaceSlack * r;
    for (std::size_t k = 0; k < capsules.size(); ++k) {
      const float gap_after = frames[k].gap + frames[k].n.dot(d);
      if (k != deepest && gap_after < entered) {
        entered = gap_after;
        other = k;
      }
    }
    if (other != deepest) {
      const Frame& f1 = frames[other];
      const float c = f0.n.dot(f1.n), det = 1.0f - c * c;
      if (!(det > 1e-6f)) return;  // exactly opposite: no side to leave by
      const float a = (-f0.gap + c * f1.gap) / det, b = (-f1.gap + c * f0.gap) / det;
      if (a >= 0.0f && b >= 0.0f) d = a * f0.n + b * f1.n;
      const float length = d.norm();
      if (length > kSqueezeReach * r) d *= kSqueezeReach * r / length;
      put_back(x, v, d, f0);
      put_back(x, v, Vec3::Zero(), f1);
    } else {
      put_back(x, v, d, f0);
    }
  }
}

bool in_box(const Vec3& lo, const Vec3& hi, const Vec3& p_lo, const Vec3& p_hi) {
  return (p_hi.array() >= lo.array()).all() && (p_lo.array() <= hi.array()).all();
}

}  // namespace

SegmentParameters closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // Ericson, Real-Time Collision Detection, 5.1.9.
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const float a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr float kTiny = 1e-12f;
  auto clamp01 = [](float x) { return std::clamp(x, 0.0f, 1.0f); };
  if (a <= kTiny && e <= kTiny) return {0.0f, 0.0f};
  if (a <= kTiny) return {0.0f, clamp01(f / e)};
  const float c = d1.dot(r);
  if (e <= kTiny) return {clamp01(-c / a), 0.0f};
  const float b = d1.dot(d2), denom = a * e - b * b;
  float s = denom > 0.0f ? clamp01((b * f - c * e) / denom) : 0.0f;
  float t = (b * s + f) / e;
  if (t < 0.0f) {
    t = 0.0f;
    s = clamp01(-c / a);
  } else if (t > 1.0f) {
    t = 1.0f;
    s = clamp01((b - c) / a);
  }
  return {s, t};
}

std::vector<std::uint32_t> guard_colliders(const ColliderTable& colliders, float dt, std::span<const Vec3> start,
                                           SolverBodies& bodies) {
  if (colliders.size() == 0) return {};
  const std::vector<Capsule> capsules = capsules_of(colliders, dt);
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Capsule& c : capsules) {
    lo = lo.cwiseMin(c.lo);
    hi = hi.cwiseMax(c.hi);
  }
  const std::int64_t rows = static_cast<std::int64_t>(bodies.rows);
  // Each thread's rows are one ascending run (static schedule), listed in thread order.
  std::vector<std::vector<std::uint32_t>> moved_by(static_cast<std::size_t>(omp_get_max_threads()));
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < rows; ++i) {
    SolverBody& body = bodies.body[i];
    Quad &x = body.position, &v = body.velocity;
    const float r = x.w;
    const Vec3 grow = Vec3::Constant(r);
    // A box around the sphere's path, from its start to where it is now.
    auto path_box = [&](Vec3& path_lo, Vec3& path_hi) {
      const Vec3 now(x.x, x.y, x.z);
      path_lo = start[i].cwiseMin(now) - grow;
      path_hi = start[i].cwiseMax(now) + grow;
    };
    Vec3 path_lo, path_hi;
    path_box(path_lo, path_hi);
    if (!in_box(lo, hi, path_lo, path_hi)) continue;
    for (int pass = 0; pass < kGuardPasses; ++pass) {
      bool moved = false;
      path_box(path_lo, path_hi);  // a push may have moved it toward another collider
      for (const Capsule& c : capsules) {
        if (!in_box(c.lo, c.hi, path_lo, path_hi)) continue;
        const Vec3 p1(x.x, x.y, x.z);
        const Frame f = frame_at(c, p1, r);
        if (pass == 0) {
          // The path's start, carried with the surface to the collider's end pose.
          const Vec3 p0 = start[i] + dt * c.surface_velocity(closest_segment_parameter(c.a0, c.b0, start[i]));
          const Frame f0 = frame_at(c, p0, r);
          Vec3 entry;
          if (f0.gap >= 0.0f && f0.n.dot(f.n) <= 0.0f && entry_point(c, p0, p1, r + c.radius, entry)) {
            put_back(x, v, entry - p1, frame_at(c, entry, r));
            moved = true;
            continue;
          }
        }
        if (inside(f, r)) {
          put_back(x, v, -f.gap * f.n, f);
          moved = true;
        }
      }
      if (!moved) break;
      if (pass == 0) moved_by[static_cast<std::size_t>(omp_get_thread_num())].push_back(static_cast<std::uint32_t>(i));
      if (pass == kGuardPasses - 1) squeeze_out(capsules, x, v);
    }
  }
  std::vector<std::uint32_t> moved;
  for (const std::vector<std::uint32_t>& rows_of_thread : moved_by) moved.insert(moved.end(), rows_of_thread.begin(), rows_of_thread.end());
  return moved;
}

}  // namespace ballpit
