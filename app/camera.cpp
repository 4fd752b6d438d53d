#include "app/camera.h"

#include <algorithm>
#include <cmath>

namespace ballpit {

Mat3 OrbitCamera::rotation() const {
  // Yaw about world Y, then pitch about the camera's X (negative: a positive pitch looks down),
  // then roll about its view axis.
  return (Eigen::AngleAxisf(yaw, Vec3::UnitY()) * Eigen::AngleAxisf(-pitch, Vec3::UnitX()) *
          Eigen::AngleAxisf(roll, Vec3::UnitZ()))
      .toRotationMatrix();
}

Vec3 OrbitCamera::eye() const { return target + rotation() * Vec3(0.0f, 0.0f, distance); }

Mat4 OrbitCamera::view() const {
  Mat3 r = rotation();
  Mat4 v = Mat4::Identity();
  v.topLeftCorner<3, 3>() = r.transpose();
  v.topRightCorner<3, 1>() = -(r.transpose() * eye());
  return v;
}

float OrbitCamera::near_plane() const { return std::max(0.01f, distance * 0.01f); }
float OrbitCamera::far_plane() const { return std::max(100.0f, distance * 20.0f); }

Mat4 OrbitCamera::projection(float aspect) const {
  const float n = near_plane(), f = far_plane();
  const float t = 1.0f / std::tan(0.5f * fov_y);
  Mat4 p = Mat4::Zero();
  p(0, 0) = t / aspect;
  p(0, 2) = -lens_shift;  // clip x += shift * w, with w = -z_view
  p(1, 1) = t;
  p(2, 2) = (f + n) / (n - f);
  p(2, 3) = 2.0f * f * n / (n - f);
  p(3, 2) = -1.0f;
  return p;
}

OrbitCamera::Projected OrbitCamera::project(const Vec3& world, const Viewport& viewport) const {
  Vec4 clip = projection(viewport.aspect()) * view() * world.homogeneous();
  Projected out;
  if (clip.w() <= 0.0f) return out;
  Vec3 ndc = clip.head<3>() / clip.w();
  out.pixel = Vec2((ndc.x() * 0.5f + 0.5f) * static_cast<float>(viewport.width),
                   (0.5f - ndc.y() * 0.5f) * static_cast<float>(viewport.height));
  out.depth = ndc.z() * 0.5f + 0.5f;
  out.visible = std::abs(ndc.x()) <= 1.0f && std::abs(ndc.y()) <= 1.0f && std::abs(ndc.z()) <= 1.0f;
  return out;
}

void OrbitCamera::orbit(float dx_px, float dy_px) {
  constexpr float kRadPerPixel = 0.005f;
  yaw -= dx_px * kRadPerPixel;
  pitch = std::clamp(pitch + dy_px * kRadPerPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(float dx_px, float dy_px, const Viewport& viewport) {
  // One pixel moves the target by one pixel's worth of world at the target's distance, so the
  // point under the cursor stays under it.
  const float metres_per_pixel = 2.0f * distance * std::tan(0.5f * fov_y) / static_cast<float>(std::max(1, viewport.height));
  target += (-dx_px * right() + dy_px * up()) * metres_per_pixel;
}

void OrbitCamera::zoom(float wheel_clicks) {
  distance = std::clamp(distance * std::exp(-0.12f * wheel_clicks), 0.2f, 2000.0f);
}

void OrbitCamera::frame_pit(float half_width, float fill_height) {
  target = Vec3(0.0f, 0.35f * fill_height, 0.0f);
  yaw = 0.55f;
  pitch = 0.62f;
  roll = 0.0f;
  // Far enough that the pit's half diagonal fits half the vertical field of view, with a margin.
  const float half_diagonal = std::max(half_width, 0.75f) * 1.4142f;
  distance = 1.3f * half_diagonal / std::tan(0.5f * fov_y);
}

void OrbitCamera::frame_character(const Vec3& root, float height) {
  target = root + Vec3(0.0f, 0.45f * height, 0.0f);
  yaw = 0.65f;
  pitch = 0.42f;
  roll = 0.0f;
  distance = 4.2f * height;
}

Vec3 gravity_from_camera(const OrbitCamera& camera, float magnitude_mps2) {
  return magnitude_mps2 * camera.down().normalized();
}

}  // namespace ballpit
