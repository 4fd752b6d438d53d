#include "systems/joint_colliders.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

#include "engine/world.h"
#include "systems/clip_sampling.h"
#include "systems/locomotion.h"

namespace ballpit {

namespace {

// Bones with fewer vertices than this get no collider: a handful of vertices (an eyelid, a
// lip) makes a shape too small to matter and too noisy to fit.
constexpr std::size_t kMinVerticesPerShape = 4;

BoneShape fit_capsule(std::uint16_t joint, const std::vector<Vec3>& p) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& q : p) c += q;
  c /= static_cast<float>(p.size());
  Mat3 cov = Mat3::Zero();
  for (const Vec3& q : p) cov += (q - c) * (q - c).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 axis = eig.eigenvectors().col(2).normalized();  // largest eigenvalue last

  // Smallest radius about the axis that holds every vertex, then the shortest segment for it:
  // vertex i at axial t_i, distance d_i from the axis is inside if the segment reaches
  // t_i -+ sqrt(r^2 - d_i^2).
  std::vector<float> t(p.size()), d(p.size());
  float r = 0.0f;
  for (std::size_t i = 0; i < p.size(); ++i) {
    Vec3 q = p[i] - c;
    t[i] = q.dot(axis);
    d[i] = (q - t[i] * axis).norm();
    r = std::max(r, d[i]);
  }
  float t0 = std::numeric_limits<float>::max(), t1 = -std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < p.size(); ++i) {
    float reach = std::sqrt(std::max(r * r - d[i] * d[i], 0.0f));
    t0 = std::min(t0, t[i] + reach);
    t1 = std::max(t1, t[i] - reach);
  }
  BoneShape s;
  s.joint = joint;
  if (t0 <= t1) {
    s.a = c + t0 * axis;
    s.b = c + t1 * axis;
    s.radius = r;
  } else {  // short and thick: a sphere about the middle holds them best
    Vec3 m = c + 0.5f * (t0 + t1) * axis;
    float rs = 0.0f;
    for (const Vec3& q : p) rs = std::max(rs, (q - m).norm());
    s.a = s.b = m;
    s.radius = rs;
  }
  return s;
}

}  // namespace

std::vector<BoneShape> fit_bone_shapes(const Model& model, ColliderKind kind) {
  const std::size_t joints = model.skeleton.size();
  std::vector<std::vector<Vec3>> driven(joints);  // vertices in each joint's bind space
  for (const SkinnedMesh& mesh : model.meshes) {
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      // weights are sorted largest first at import: slot 0 is the dominant bone
      const std::uint16_t bone = mesh.bones[v][0];
      driven[mesh.bone_joint[bone]].push_back(mesh.inverse_bind[bone] * mesh.positions[v]);
    }
  }
  std::vector<BoneShape> shapes;
  for (std::size_t j = 0; j < joints; ++j) {
    if (driven[j].size() < kMinVerticesPerShape) continue;
    BoneShape s = fit_capsule(static_cast<std::uint16_t>(j), driven[j]);
    if (kind == ColliderKind::Spheres) s.a = s.b = Vec3::Zero();
    if (s.radius > 0.0f) shapes.push_back(s);
  }
  return shapes;
}

ColliderReach collider_reach(const CharacterSetup& setup) {
  const Model& model = *setup.model;
  RootState origin;  // root at the origin, heading 0: character space
  const Affine3 w = character_transform(setup, origin);
  ClipCursor cursor;
  cursor.reset(model.skeleton.size());
  LocalPose local;
  std::vector<Affine3> m;
  ColliderReach reach;
  reach.lowest = std::numeric_limits<float>::max();
  std::vector<std::size_t> clips(setup.clips.begin(), setup.clips.end());
  for (std::int32_t action : setup.actions)
    if (action >= 0) clips.push_back(static_cast<std::size_t>(action));
  for (std::size_t c : clips) {
    const Clip& clip = model.clips[c];
    const int samples = clip.duration > 0.0f ? kReachSamples : 1;
    for (int i = 0; i < samples; ++i) {
      sample_clip(clip, clip.duration * static_cast<float>(i) / static_cast<float>(samples), cursor, local);
      local_to_model(model.skeleton, local, m);
      for (const BoneShape& s : setup.shapes) {
        const float r = s.radius * setup.scale;
        for (const Vec3& end : {Vec3(w * (m[s.joint] * s.a)), Vec3(w * (m[s.joint] * s.b))}) {
          reach.footprint_radius = std::max(reach.footprint_radius, std::hypot(end.x(), end.z()) + r);
          reach.lowest = std::min(reach.lowest, end.y() - r);
        }
      }
    }
  }
  return reach;
}

void update_colliders(World& world, std::size_t i) {
  const CharacterSetup& setup = world.characters.setup(i);
  const CharacterMotion& motion = world.characters.motion(i);
  const CharacterPose& pose = world.characters.pose(i);
  const float inv_dt = 1.0f / world.step();
  const Affine3 w0 = character_transform(setup, motion.previous);
  const Affine3 w1 = character_transform(setup, motion.current);
  for (std::size_t k = 0; k < setup.shapes.size(); ++k) {
    const BoneShape& s = setup.shapes[k];
    const Affine3 m0 = w0 * pose.model_previous[s.joint];
    const Affine3 m1 = w1 * pose.model[s.joint];
    const Vec3 a0 = m0 * s.a, a1 = m1 * s.a;
    const Vec3 b0 = m0 * s.b, b1 = m1 * s.b;
    world.colliders.set_pose(setup.first_collider + static_cast<std::uint32_t>(k), a0, b0, (a1 - a0) * inv_dt,
                             (b1 - b0) * inv_dt);
  }
}

Access JointColliderSystem::access() const {
  Access a;
  a.reads = {ColumnId::CharacterPose, ColumnId::CharacterController};
  a.writes = {ColumnId::Colliders};
  return a;
}

void JointColliderSystem::run(World& world) {
  for (std::size_t i = 0; i < world.characters.size(); ++i) update_colliders(world, i);
}

ColliderOverlap measure_collider_overlap(const World& world, float depth_fraction) {
  ColliderOverlap out;
  const ColliderTable& c = world.colliders;
  const std::size_t nc = c.size();
  if (nc == 0) return out;
  const float dt = world.step();
  std::vector<Vec3> a(nc), b(nc);
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (std::size_t k = 0; k < nc; ++k) {
    a[k] = c.a()[k] + c.velocity_a()[k] * dt;
    b[k] = c.b()[k] + c.velocity_b()[k] * dt;
    lo = lo.cwiseMin(a[k].cwiseMin(b[k]) - Vec3::Constant(c.radius()[k]));
    hi = hi.cwiseMax(a[k].cwiseMax(b[k]) + Vec3::Constant(c.radius()[k]));
  }
  auto x = world.spheres.position();
  auto r = world.spheres.radius();
  const std::int64_t n = static_cast<std::int64_t>(x.size());
  double deepest = 0.0;
  std::size_t inside = 0;
  // max and integer sum: exact, so the reduction order does not matter
#pragma omp parallel for schedule(static) reduction(max : deepest) reduction(+ : inside)
  for (std::int64_t i = 0; i < n; ++i) {
    if ((x[i].array() < lo.array() - r[i]).any() || (x[i].array() > hi.array() + r[i]).any()) continue;
    double worst = 0.0;
    for (std::size_t k = 0; k < nc; ++k) {
      const float t = closest_segment_parameter(a[k], b[k], x[i]);
      const float dist = (x[i] - (a[k] + t * (b[k] - a[k]))).norm();
      worst = std::max(worst, static_cast<double>(r[i] + c.radius()[k] - dist) / r[i]);
    }
    deepest = std::max(deepest, worst);
    if (worst > depth_fraction) ++inside;
  }
  out.max_depth_r = deepest;
  out.inside = inside;
  return out;
}

ColliderMotion measure_collider_motion(const World& world) {
  ColliderMotion out;
  const ColliderTable& c = world.colliders;
  const float dt = world.step();
  for (std::size_t k = 0; k < c.size(); ++k) {
    out.fastest = std::max(out.fastest, static_cast<double>(c.speed(k)));
    const float top = std::max(c.a()[k].y() + c.velocity_a()[k].y() * dt, c.b()[k].y() + c.velocity_b()[k].y() * dt);
    out.highest = std::max(out.highest, static_cast<double>(top + c.radius()[k]));
  }
  return out;
}

double struck_ball_speed_bound(const ColliderMotion& over_the_run, float restitution, float push_out_speed,
                               float gravity) {
  const double strike = (1.0 + restitution) * over_the_run.fastest + push_out_speed;
  return std::sqrt(strike * strike + 2.0 * static_cast<double>(gravity) * over_the_run.highest);
}

}  // namespace ballpit
