// The orbit camera: projection to pixels, and gravity that follows the camera's down
// direction (the app's "slosh the balls" mode). Pure math, no OpenGL.
#include <gtest/gtest.h>

#include <cmath>

#include "app/camera.h"

using namespace ballpit;

namespace {

constexpr float kG = 9.81f;           // (unit: m/s^2)
constexpr float kQuarterTurn = 1.5707963f;
// Angles come from float rotations and an acos near 0 or pi/2: 1e-3 rad is far above float
// rounding there and far below any visible error.
constexpr float kAngleTolerance = 1e-3f;  // (unit: rad)

float angle_between(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0f, 1.0f));
}

}  // namespace

TEST(CameraGravity, ALevelCameraGivesPlainDownwardGravity) {
  OrbitCamera c;
  c.pitch = 0.0f;
  Vec3 g = gravity_from_camera(c, kG);
  EXPECT_NEAR(g.x(), 0.0f, 1e-5f);
  EXPECT_NEAR(g.y(), -kG, 1e-5f);
  EXPECT_NEAR(g.z(), 0.0f, 1e-5f);
}

TEST(CameraGravity, RollingTheCameraAQuarterTurnTurnsGravityAQuarterTurn) {
  OrbitCamera c;
  c.pitch = 0.0f;
  c.yaw = 0.3f;
  Vec3 before = gravity_from_camera(c, kG);
  c.roll += kQuarterTurn;
  Vec3 after = gravity_from_camera(c, kG);
  EXPECT_NEAR(angle_between(before, after), kQuarterTurn, kAngleTolerance);
  EXPECT_NEAR(after.norm(), kG, 1e-4f);  // turned, not scaled
  EXPECT_NEAR(after.y(), 0.0f, 1e-4f);   // now horizontal: the balls slosh sideways
}

TEST(CameraGravity, PitchingTheCameraAQuarterTurnTurnsGravityAQuarterTurn) {
  OrbitCamera c;
  c.pitch = 0.0f;
  Vec3 before = gravity_from_camera(c, kG);
  c.orbit(0.0f, kQuarterTurn / 0.005f);  // the mouse drag that pitches by 90 degrees
  EXPECT_NEAR(c.pitch, kQuarterTurn, 1e-5f);
  Vec3 after = gravity_from_camera(c, kG);
  EXPECT_NEAR(angle_between(before, after), kQuarterTurn, kAngleTolerance);
  EXPECT_NEAR(after.norm(), kG, 1e-4f);
}

TEST(CameraGravity, OrbitingARolledCameraAQuarterTurnTurnsGravityAQuarterTurn) {
  // Rolled a quarter turn, gravity is horizontal; orbiting about the vertical then turns it
  // with the camera, as sloshing needs.
  OrbitCamera c;
  c.pitch = 0.0f;
  c.roll = kQuarterTurn;
  Vec3 before = gravity_from_camera(c, kG);
  c.yaw += kQuarterTurn;
  Vec3 after = gravity_from_camera(c, kG);
  EXPECT_NEAR(angle_between(before, after), kQuarterTurn, kAngleTolerance);
}

TEST(CameraGravity, OrbitingAnUnrolledLevelCameraLeavesGravityAlone) {
  OrbitCamera c;
  c.pitch = 0.0f;
  Vec3 before = gravity_from_camera(c, kG);
  c.yaw += kQuarterTurn;
  EXPECT_NEAR(angle_between(before, gravity_from_camera(c, kG)), 0.0f, kAngleTolerance);
}

TEST(CameraProjection, TheTargetProjectsToTheCentreShiftedByTheLens) {
  OrbitCamera c;
  c.target = Vec3(1.0f, 2.0f, -3.0f);
  c.yaw = 0.7f;
  c.pitch = 0.4f;
  const Viewport v{640, 360};
  OrbitCamera::Projected p = c.project(c.target, v);
  ASSERT_TRUE(p.visible);
  EXPECT_NEAR(p.pixel.x(), 320.0f, 1e-3f);
  EXPECT_NEAR(p.pixel.y(), 180.0f, 1e-3f);
  c.lens_shift = 0.25f;  // a quarter of the half width: 80 pixels right
  EXPECT_NEAR(c.project(c.target, v).pixel.x(), 400.0f, 1e-3f);
}

TEST(CameraProjection, UpInTheWorldIsUpOnTheScreen) {
  OrbitCamera c;
  const Viewport v{640, 360};
  float y0 = c.project(c.target, v).pixel.y();
  float y1 = c.project(c.target + Vec3(0.0f, 0.5f, 0.0f), v).pixel.y();
  EXPECT_LT(y1, y0);  // pixel rows count down from the top
  EXPECT_FALSE(c.project(c.eye() - 2.0f * c.forward(), v).visible);  // behind the eye
}
