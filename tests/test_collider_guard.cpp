// The joint-collider guard alone: one still capsule and a few spheres whose paths over a step
// are given (start, and where the substeps left them).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "systems/collider_guard.h"

namespace ballpit {
namespace {

constexpr float kDt = 1.0f / 60.0f;
constexpr float kR = 0.04f;

// An upright capsule of radius 0.05 m on the y axis, from y = 0.8 to 1.2, at rest.
ColliderTable still_capsule() {
  ColliderTable table;
  ColliderDesc d;
  d.shape = ColliderShape::Capsule;
  d.a = Vec3(0.0f, 0.8f, 0.0f);
  d.b = Vec3(0.0f, 1.2f, 0.0f);
  d.radius = 0.05f;
  table.add(d);
  return table;
}

struct Guarded {
  std::vector<Vec3> start;
  SolverBodies bodies;

  void add(const Vec3& from, const Vec3& to, const Vec3& velocity) {
    start.push_back(from);
    SolverBody b{};
    b.velocity = {velocity.x(), velocity.y(), velocity.z(), 20.0f};
    b.position = {to.x(), to.y(), to.z(), kR};
    bodies.body.push_back(b);
    bodies.rows = start.size();
  }
  Vec3 position(std::size_t i) const {
    const Quad& p = bodies.body[i].position;
    return {p.x, p.y, p.z};
  }
  Vec3 velocity(std::size_t i) const {
    const Quad& v = bodies.body[i].velocity;
    return {v.x, v.y, v.z};
  }
};

TEST(ColliderGuard, ClosestSegmentParametersOfCrossingParallelAndDegenerateSegments) {
  const SegmentParameters cross = closest_segment_parameters(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0.5f, -1, 1), Vec3(0.5f, 1, 1));
  EXPECT_FLOAT_EQ(cross.s, 0.75f);
  EXPECT_FLOAT_EQ(cross.t, 0.5f);
  // Parallel and overlapping: any pair at distance 1 is closest; the one found must be at it.
  const SegmentParameters parallel = closest_segment_parameters(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0), Vec3(3, 1, 0));
  const Vec3 p = Vec3(2 * parallel.s, 0, 0), q = Vec3(1 + 2 * parallel.t, 1, 0);
  EXPECT_FLOAT_EQ((p - q).norm(), 1.0f);
  const SegmentParameters point = closest_segment_parameters(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(-1, 2, 0), Vec3(1, 2, 0));
  EXPECT_FLOAT_EQ(point.s, 0.0f);
  EXPECT_FLOAT_EQ(point.t, 0.5f);
  const SegmentParameters past_end = closest_segment_parameters(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, -1, 0), Vec3(3, 1, 0));
  EXPECT_FLOAT_EQ(past_end.s, 1.0f);
  EXPECT_FLOAT_EQ(past_end.t, 0.5f);
}

TEST(ColliderGuard, ASphereThatCrossedTheAxisGoesBackToWhereItEntered) {
  // Contact distance 0.09 m from the axis. One sphere ends past the axis but inside, one went
  // clean through: both are put back at x = -0.09, on the side they came from, and stopped
  // along the normal (the guard adds no bounce).
  const ColliderTable capsule = still_capsule();
  Guarded g;
  g.add(Vec3(-0.2f, 1.0f, 0.0f), Vec3(0.03f, 1.0f, 0.0f), Vec3(10.0f, 0.0f, 0.0f));
  g.add(Vec3(-0.2f, 1.0f, 0.0f), Vec3(0.2f, 1.0f, 0.0f), Vec3(20.0f, 0.0f, 0.0f));
  guard_colliders(capsule, kDt, g.start, g.bodies);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR(g.position(i).x(), -0.09f, 1e-5f) << "sphere " << i;
    EXPECT_FLOAT_EQ(g.position(i).y(), 1.0f);
    EXPECT_FLOAT_EQ(g.velocity(i).x(), 0.0f);
  }
}

TEST(ColliderGuard, ASphereJustInsideOnItsOwnSideIsPushedOutAlongTheNormalAndKeepsItsSlide) {
  // Sliding down the capsule's side and ending 0.005 m inside: it leaves along the normal (x),
  // and its slide (y) is kept, position and velocity.
  const ColliderTable capsule = still_capsule();
  Guarded g;
  g.add(Vec3(-0.09f, 1.1f, 0.0f), Vec3(-0.085f, 1.0f, 0.0f), Vec3(0.3f, -6.0f, 0.0f));
  guard_colliders(capsule, kDt, g.start, g.bodies);
  EXPECT_NEAR(g.position(0).x(), -0.09f, 1e-6f);
  EXPECT_FLOAT_EQ(g.position(0).y(), 1.0f);
  EXPECT_FLOAT_EQ(g.velocity(0).x(), 0.0f);
  EXPECT_FLOAT_EQ(g.velocity(0).y(), -6.0f);
}

TEST(ColliderGuard, SpheresClearOfTheCapsuleOrPassingAnEndAreLeftAlone) {
  const ColliderTable capsule = still_capsule();
  Guarded g;
  g.add(Vec3(1.0f, 1.0f, 0.0f), Vec3(1.1f, 1.0f, 0.0f), Vec3(6.0f, 0.0f, 0.0f));      // far away
  g.add(Vec3(-0.2f, 1.3f, 0.0f), Vec3(0.2f, 1.3f, 0.0f), Vec3(24.0f, 0.0f, 0.0f));    // over the top cap
  g.add(Vec3(-0.095f, 1.0f, 0.0f), Vec3(-0.091f, 1.0f, 0.0f), Vec3(0.2f, 0.0f, 0.0f));  // touching, not in
  const std::vector<SolverBody> before(g.bodies.body.begin(), g.bodies.body.end());
  guard_colliders(capsule, kDt, g.start, g.bodies);
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(g.position(i), Vec3(before[i].position.x, before[i].position.y, before[i].position.z)) << "sphere " << i;
    EXPECT_EQ(g.velocity(i), Vec3(before[i].velocity.x, before[i].velocity.y, before[i].velocity.z)) << "sphere " << i;
  }
}

TEST(ColliderGuard, ASphereTheCapsuleSweptOverIsPutInFrontOfIt) {
  // The capsule moves +x at 12 m/s (0.2 m this step) onto a sphere at rest that the contacts
  // failed to push: seen from the capsule, the sphere came from 0.2 m ahead and ended behind
  // the axis. It goes in front (x > 0 of the capsule's end pose at x = 0.2) with the capsule's speed.
  ColliderTable table;
  ColliderDesc d;
  d.shape = ColliderShape::Capsule;
  d.a = Vec3(0.0f, 0.8f, 0.0f);
  d.b = Vec3(0.0f, 1.2f, 0.0f);
  d.radius = 0.05f;
  d.velocity_a = d.velocity_b = Vec3(12.0f, 0.0f, 0.0f);
  table.add(d);
  Guarded g;
  g.add(Vec3(0.17f, 1.0f, 0.0f), Vec3(0.17f, 1.0f, 0.0f), Vec3::Zero());
  guard_colliders(table, kDt, g.start, g.bodies);
  EXPECT_NEAR(g.position(0).x(), 0.2f + 0.09f, 1e-5f);
  EXPECT_NEAR(g.velocity(0).x(), 12.0f, 1e-5f);
}

TEST(ColliderGuard, APinchedSphereLeavesByTheOpeningBetweenTheColliders) {
  // Two capsules in a V about z, 0.16 m apart at z = 0 and parting toward -z: a sphere between
  // them at z = 0 overlaps both, and pushing it out of each in turn only pushes it into the
  // other. Room for it (0.18 m) is at z <= -0.13; it must end there, in neither, at its height.
  ColliderTable table;
  ColliderDesc d;
  d.shape = ColliderShape::Capsule;
  d.radius = 0.05f;
  d.a = Vec3(-0.08f, 1.0f, -0.2f);
  d.b = Vec3(-0.08f, 1.0f, 0.2f);
  table.add(d);
  d.a = Vec3(0.11f, 1.0f, -0.2f);
  d.b = Vec3(0.05f, 1.0f, 0.2f);
  table.add(d);
  Guarded g;
  g.add(Vec3(0.0f, 1.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), Vec3::Zero());
  guard_colliders(table, kDt, g.start, g.bodies);
  const Vec3 x = g.position(0);
  for (std::size_t k = 0; k < table.size(); ++k) {
    const Vec3 a = table.a()[k], b = table.b()[k];
    const float gap = (x - (a + closest_segment_parameter(a, b, x) * (b - a))).norm() - kR - d.radius;
    EXPECT_GE(gap, -0.001f * kR) << "collider " << k << ", sphere at " << x.transpose();
  }
  EXPECT_LT(x.z(), -0.12f);
  EXPECT_NEAR(x.y(), 1.0f, 1e-6f);
}

TEST(ColliderGuard, APinchTooLongToLeaveInOneStepIsNotFlung) {
  // The same pinch between two 2 m capsules that lie almost side by side (the gap opens by 4 mm
  // over their length, never to the 0.18 m the sphere needs): to first order the way out is
  // metres long. The sphere moves at most 4 moves of 2 r (plus the passes' 0.01 m pushes), and
  // along the capsules, not off them.
  ColliderTable table;
  ColliderDesc d;
  d.shape = ColliderShape::Capsule;
  d.radius = 0.05f;
  d.a = Vec3(-0.08f, 1.0f, -1.0f);
  d.b = Vec3(-0.08f, 1.0f, 1.0f);
  table.add(d);
  d.a = Vec3(0.082f, 1.0f, -1.0f);
  d.b = Vec3(0.078f, 1.0f, 1.0f);
  table.add(d);
  Guarded g;
  g.add(Vec3(0.0f, 1.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), Vec3::Zero());
  guard_colliders(table, kDt, g.start, g.bodies);
  const Vec3 moved = g.position(0) - Vec3(0.0f, 1.0f, 0.0f);
  EXPECT_LE(moved.norm(), 8.0f * kR + 0.02f) << moved.transpose();
  EXPECT_LE(std::abs(moved.x()), 0.02f);
  EXPECT_NEAR(moved.y(), 0.0f, 1e-6f);
}

}  // namespace
}  // namespace ballpit
