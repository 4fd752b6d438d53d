// The marine's body (engine/marine/marine_body.h): its size, its skin weights, a closed surface
// with unit normals, where its colours are, and how well the skin keeps its volume when the
// knee and the elbow bend deeply under linear blend skinning.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include "engine/marine/camouflage.h"
#include "engine/marine/marine_body.h"
#include "engine/marine/marine_skeleton.h"
#include "systems/clip_sampling.h"

namespace ballpit::marine {
namespace {

const SkinnedMesh& body() {
  static const SkinnedMesh mesh = make_body(make_skeleton());
  return mesh;
}

// Skinned positions (linear blend skinning) with the given local rotations on a rest pose.
std::vector<Vec3> skin(const SkinnedMesh& mesh, const std::vector<std::pair<Joint, Quat>>& rotations,
                       std::vector<Affine3>& model) {
  const Skeleton sk = make_skeleton();
  LocalPose pose;
  rest_pose(sk, pose);
  for (const auto& [j, q] : rotations) pose.rotation[j] = q;
  local_to_model(sk, pose, model);
  std::vector<Vec3> out(mesh.positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < kMaxInfluences; ++k) {
      const int b = mesh.bones[v][k];
      p += mesh.weights[v][k] * (model[mesh.bone_joint[b]] * (mesh.inverse_bind[b] * mesh.positions[v]));
    }
    out[v] = p;
  }
  return out;
}

// Enclosed volume by the divergence theorem (unit: m^3); positive when faces wind outwards.
double volume(const SkinnedMesh& mesh, const std::vector<Vec3>& p) {
  double v = 0.0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3& a = p[mesh.indices[t]];
    const Vec3& b = p[mesh.indices[t + 1]];
    const Vec3& c = p[mesh.indices[t + 2]];
    v += static_cast<double>(a.dot(b.cross(c))) / 6.0;
  }
  return v;
}

// The volume around a joint: the cones from the joint to the triangles whose bind centroid
// lies within `radius` of the joint's bind position (unit: m^3), the joint taken where the
// pose puts it. It falls when the skin around the joint caves in.
double joint_volume(const SkinnedMesh& mesh, const std::vector<Vec3>& p, const Vec3& bind_joint, const Vec3& joint,
                    float radius) {
  double v = 0.0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const std::uint32_t i = mesh.indices[t], j = mesh.indices[t + 1], k = mesh.indices[t + 2];
    const Vec3 centroid = (mesh.positions[i] + mesh.positions[j] + mesh.positions[k]) / 3.0f;
    if ((centroid - bind_joint).norm() > radius) continue;
    v += static_cast<double>((p[i] - joint).dot((p[j] - joint).cross(p[k] - joint))) / 6.0;
  }
  return v;
}

// The smallest ratio, posed to bind, of a vertex's distance from the joint over the vertices
// of the joint's own limb within `radius` of it: 0 would mean the skin collapsed onto the bone.
float closest_approach(const SkinnedMesh& mesh, const std::vector<Vec3>& p, const Vec3& bind_joint, const Vec3& joint,
                       float radius, float side_x) {
  float worst = 1e9f;
  for (std::size_t v = 0; v < p.size(); ++v) {
    const float d0 = (mesh.positions[v] - bind_joint).norm();
    if (d0 > radius || mesh.positions[v].x() * side_x <= 0.0f) continue;
    worst = std::min(worst, (p[v] - joint).norm() / d0);
  }
  return worst;
}

TEST(MarineBody, StandsOnePointEightMetresFromSoleToHelmet) {
  float lo = 1e9f, hi = -1e9f;
  for (const Vec3& p : body().positions) lo = std::min(lo, p.y()), hi = std::max(hi, p.y());
  // Vertices lie on the surface to well under a millimetre (Newton steps); 1 cm is the spec.
  EXPECT_NEAR(lo, 0.0f, 0.005f);
  EXPECT_NEAR(hi - lo, kStature, 0.01f);
}

TEST(MarineBody, IsDetailedEnough) {
  EXPECT_GE(body().indices.size() / 3, 10000u);
  EXPECT_LE(body().indices.size() / 3, 40000u);
  EXPECT_EQ(body().name, "marine");
}

TEST(MarineBody, IsTheSameBitsEveryBuild) {
  const SkinnedMesh again = make_body(make_skeleton());
  ASSERT_EQ(again.positions.size(), body().positions.size());
  ASSERT_EQ(again.indices, body().indices);
  EXPECT_EQ(std::memcmp(again.positions.data(), body().positions.data(), again.positions.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(again.weights.data(), body().weights.data(), again.weights.size() * sizeof(again.weights[0])), 0);
  EXPECT_EQ(again.colors, body().colors);
}

TEST(MarineBody, EveryVertexHasAtMostFourNormalisedWeightsLargestFirst) {
  const SkinnedMesh& m = body();
  ASSERT_EQ(m.bones.size(), m.positions.size());
  ASSERT_EQ(m.weights.size(), m.positions.size());
  ASSERT_EQ(m.bone_joint.size(), static_cast<std::size_t>(kJoints));
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    float sum = 0.0f;
    for (int k = 0; k < kMaxInfluences; ++k) {
      ASSERT_LT(m.bones[v][k], m.bone_joint.size());
      ASSERT_GE(m.weights[v][k], 0.0f);
      if (k > 0) {
        ASSERT_LE(m.weights[v][k], m.weights[v][k - 1]);
      }
      sum += m.weights[v][k];
    }
    ASSERT_NEAR(sum, 1.0f, 1e-5f) << "vertex " << v;
  }
}

TEST(MarineBody, BonesAreTheJointsWithTranslationInverseBinds) {
  const SkinnedMesh& m = body();
  const auto bind = bind_positions();
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_EQ(m.bone_joint[j], j);
    EXPECT_LT((m.inverse_bind[j] * bind[j]).norm(), 1e-6f);
    EXPECT_TRUE(m.inverse_bind[j].linear().isIdentity(1e-6f));
  }
}

TEST(MarineBody, ALegNeverTakesWeightFromTheOtherLegOrAnArm) {
  const SkinnedMesh& m = body();
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3& p = m.positions[v];
    if (p.y() > 0.75f) continue;  // below the crotch: every vertex is on one leg
    const bool left = p.x() > 0.0f;
    for (int k = 0; k < kMaxInfluences; ++k) {
      if (m.weights[v][k] == 0.0f) continue;
      const Joint j = static_cast<Joint>(m.bone_joint[m.bones[v][k]]);
      ASSERT_TRUE(j >= kLeftUpLeg) << "vertex " << v << " takes weight from joint " << j;
      ASSERT_EQ(is_left(j), left) << "vertex " << v;
    }
  }
}

TEST(MarineBody, GearFollowsItsBones) {
  const SkinnedMesh& m = body();
  auto nearest = [&](const Vec3& q) {
    std::size_t best = 0;
    for (std::size_t v = 1; v < m.positions.size(); ++v)
      if ((m.positions[v] - q).squaredNorm() < (m.positions[best] - q).squaredNorm()) best = v;
    return best;
  };
  // The helmet is rigid on the head: its crown and its brim are the Head's alone.
  for (const Vec3& q : {Vec3(0.0f, 2.0f, 0.0f), Vec3(0.0f, 1.74f, 0.4f), Vec3(0.3f, 1.70f, 0.0f)}) {
    const std::size_t v = nearest(q);
    EXPECT_EQ(m.bone_joint[m.bones[v][0]], kHead) << q.transpose();
    EXPECT_GT(m.weights[v][0], 0.999f) << q.transpose();
  }
  // The plate carrier's front and back ride on the upper spine.
  for (const Vec3& q : {Vec3(0.0f, 1.25f, 0.5f), Vec3(0.0f, 1.25f, -0.5f)}) {
    const std::size_t v = nearest(q);
    const int j = m.bone_joint[m.bones[v][0]];
    EXPECT_TRUE(j == kSpine1 || j == kSpine2) << q.transpose() << " on joint " << j;
  }
}

TEST(MarineBody, IsClosedWithOutwardWindingAndUnitNormals) {
  const SkinnedMesh& m = body();
  ASSERT_EQ(m.indices.size() % 3, 0u);
  // Every directed edge once and its reverse once: each edge borders exactly two triangles,
  // wound consistently.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t t = 0; t < m.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) ++directed[{m.indices[t + e], m.indices[t + (e + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1);
    ASSERT_TRUE(directed.count({edge.second, edge.first})) << edge.first << "-" << edge.second;
  }
  EXPECT_GT(volume(m, m.positions), 0.05);  // outward winding; a 1.8 m man with gear ~0.09 m^3
  for (const Vec3& n : m.normals) ASSERT_NEAR(n.norm(), 1.0f, 1e-4f);
}

TEST(MarineBody, IsSkinAtTheFaceAndHandsBootsBelowCamouflageOnTheLegs) {
  const SkinnedMesh& m = body();
  ASSERT_EQ(m.colors.size(), m.positions.size());
  EXPECT_EQ(m.base_color, Vec4::Ones());
  auto nearest = [&](const Vec3& q) {
    std::size_t best = 0;
    for (std::size_t v = 1; v < m.positions.size(); ++v)
      if ((m.positions[v] - q).squaredNorm() < (m.positions[best] - q).squaredNorm()) best = v;
    return m.colors[best];
  };
  const auto P = bind_positions();
  EXPECT_EQ(nearest(Vec3(0.0f, 1.63f, 0.4f)), kSkinTone);  // in front of his mouth
  const Vec3 dir = (P[kLeftHand] - P[kLeftForeArm]).normalized();
  EXPECT_EQ(nearest(P[kLeftHand] + 0.25f * dir), kSkinTone);  // beyond his fingertips
  EXPECT_TRUE(is_camo_color(nearest(Vec3(0.30f, 0.72f, 0.0f))));  // outside the left thigh
  EXPECT_TRUE(is_camo_color(nearest(Vec3(0.0f, 2.0f, 0.0f))));   // above the helmet
  EXPECT_EQ(nearest(Vec3(0.0f, 1.15f, 0.5f)), kGearCoyote);      // the plate carrier's front
  int lowest = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v].y() < 0.01f) {
      EXPECT_EQ(m.colors[v], kBootTan);
      ++lowest;
    }
  EXPECT_GT(lowest, 20);
  // All four camouflage colours are there, each on at least 5 % of the uniform's vertices.
  std::map<Srgb8, int> count;
  for (const Srgb8& c : m.colors) ++count[c];
  int camo = 0;
  for (const Srgb8& c : {kCamoKhaki, kCamoGreen, kCamoBrown, kCamoBlack}) camo += count[c];
  for (const Srgb8& c : {kCamoKhaki, kCamoGreen, kCamoBrown, kCamoBlack}) EXPECT_GT(count[c], camo / 20);
  for (const Srgb8& c : m.colors) EXPECT_EQ(c[3], 255);
}

// Deep bends under linear blend skinning: the knee at 110 degrees and the elbow at 120.
// LBS shrinks the inside of a bend: a vertex weighted half and half across a joint bent by
// theta lands at the mean of its two rigid images, cos(theta / 2) of its distance from the
// joint (0.57 at the knee, 0.50 at the elbow); no weighting does better, and a torn or
// collapsed joint does far worse (vertices near 0, or lost volume). Measured (2026-12, cell
// 1.7 cm): whole mesh -0.26 % (knee) and -0.19 % (elbow); the cones within 12 cm of the joint
// keep 83.4 % (knee) and 82.8 % (elbow) of their bind volume; the closest any limb vertex
// within 12 cm comes to the joint is 0.58 (knee) and 0.50 (elbow) of its bind distance, which
// is the LBS limit above.
constexpr double kWholeVolumeChange = 0.01;  // measured 0.26 %: a knee's 12 cm holds ~3 % of him
constexpr double kLocalVolumeKept = 0.75;    // measured 0.83; a collapsed joint keeps ~0.5
constexpr float kApproachOfLbsLimit = 0.9f;  // of cos(theta / 2): 10 % for mesh noise
constexpr float kJointRadius = 0.12f;        // (unit: m)

TEST(MarineBody, KeepsItsVolumeWhenTheKneeBendsDeeply) {
  const SkinnedMesh& m = body();
  const auto P = bind_positions();
  std::vector<Affine3> model;
  const auto posed = skin(m, {{kLeftLeg, Quat(Eigen::AngleAxisf(110.0f * 3.14159265f / 180.0f, Vec3::UnitX()))}}, model);
  const double v0 = volume(m, m.positions), v1 = volume(m, posed);
  const Vec3 knee = model[kLeftLeg].translation();
  const double l0 = joint_volume(m, m.positions, P[kLeftLeg], P[kLeftLeg], kJointRadius);
  const double l1 = joint_volume(m, posed, P[kLeftLeg], knee, kJointRadius);
  const float approach = closest_approach(m, posed, P[kLeftLeg], knee, kJointRadius, 1.0f);
  std::printf("knee 110 deg: whole volume %.5f -> %.5f m^3 (%+.2f %%), within 12 cm %.2f %%, closest approach %.2f\n", v0,
              v1, 100.0 * (v1 / v0 - 1.0), 100.0 * l1 / l0, approach);
  EXPECT_LT(std::abs(v1 / v0 - 1.0), kWholeVolumeChange);
  EXPECT_GT(l1 / l0, kLocalVolumeKept);
  EXPECT_GT(approach, kApproachOfLbsLimit * std::cos(0.5f * 110.0f * 3.14159265f / 180.0f));
}

TEST(MarineBody, KeepsItsVolumeWhenTheElbowBendsDeeply) {
  const SkinnedMesh& m = body();
  const auto P = bind_positions();
  const Vec3 dir = (P[kLeftHand] - P[kLeftForeArm]).normalized();
  const Vec3 axis = dir.cross(Vec3::UnitZ()).normalized();  // flexion: the hand comes forward
  std::vector<Affine3> model;
  const auto posed = skin(m, {{kLeftForeArm, Quat(Eigen::AngleAxisf(120.0f * 3.14159265f / 180.0f, axis))}}, model);
  const double v0 = volume(m, m.positions), v1 = volume(m, posed);
  const Vec3 elbow = model[kLeftForeArm].translation();
  const double l0 = joint_volume(m, m.positions, P[kLeftForeArm], P[kLeftForeArm], kJointRadius);
  const double l1 = joint_volume(m, posed, P[kLeftForeArm], elbow, kJointRadius);
  const float approach = closest_approach(m, posed, P[kLeftForeArm], elbow, kJointRadius, 1.0f);
  std::printf("elbow 120 deg: whole volume %.5f -> %.5f m^3 (%+.2f %%), within 12 cm %.2f %%, closest approach %.2f\n",
              v0, v1, 100.0 * (v1 / v0 - 1.0), 100.0 * l1 / l0, approach);
  EXPECT_LT(std::abs(v1 / v0 - 1.0), kWholeVolumeChange);
  EXPECT_GT(l1 / l0, kLocalVolumeKept);
  EXPECT_GT(approach, kApproachOfLbsLimit * std::cos(0.5f * 120.0f * 3.14159265f / 180.0f));
}

}  // namespace
}  // namespace ballpit::marine
