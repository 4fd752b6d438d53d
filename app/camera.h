// The orbit camera: yaw, pitch and roll about a target point, at a distance. It owns the view
// and projection matrices, projects world points to pixels (tests use it), and gives the
// camera's down direction, which the app can make the balls' gravity.
// Decision: the view is built from the camera's rotation, never from lookAt with a fixed up
// vector, so pitch may reach +-90 degrees and roll may be anything with no singularity.
#pragma once

#include "engine/math.h"

namespace ballpit {

struct Viewport {
  int width = 1280;   // (unit: pixel)
  int height = 720;   // (unit: pixel)
  float aspect() const { return height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f; }
};

class OrbitCamera {
 public:
  static constexpr float kMaxPitch = 1.5707963f;  // straight down / straight up (unit: rad)

  Vec3 target = Vec3::Zero();  // the point orbited (unit: m)
  float distance = 5.0f;       // eye to target (unit: m)
  float yaw = 0.0f;            // about world +Y; 0 puts the eye on the +Z side (unit: rad)
  float pitch = 0.5f;          // positive looks down at the target (unit: rad)
  float roll = 0.0f;           // about the view axis (unit: rad)
  float fov_y = 0.785398f;     // vertical field of view (unit: rad)
  // Horizontal lens shift in normalised device units (2 = the viewport's width): moves the
  // image sideways without turning the camera, to centre the scene beside the HUD panel.
  float lens_shift = 0.0f;

  // Camera-to-world rotation: the camera looks along its local -Z with +Y up.
  Mat3 rotation() const;
  Vec3 eye() const;
  Vec3 forward() const { return rotation() * Vec3(0.0f, 0.0f, -1.0f); }
  Vec3 up() const { return rotation() * Vec3(0.0f, 1.0f, 0.0f); }
  Vec3 right() const { return rotation() * Vec3(1.0f, 0.0f, 0.0f); }
  // The screen's down direction in the world: where gravity points when it follows the camera.
  Vec3 down() const { return -up(); }

  Mat4 view() const;
  // OpenGL clip space (z in [-w, w]); near and far follow the distance so depth precision
  // stays useful from a close-up of the character to a 1M-ball pit.
  Mat4 projection(float aspect) const;
  float near_plane() const;
  float far_plane() const;

  // Pixel coordinates of a world point (x right, y down from the top-left corner) and its
  // depth in [0, 1]; visible is false behind the eye or outside the viewport.
  struct Projected {
    Vec2 pixel = Vec2::Zero();
    float depth = 0.0f;
    bool visible = false;
  };
  Projected project(const Vec3& world, const Viewport& viewport) const;

  // Mouse-style controls; amounts are in pixels of mouse motion or wheel clicks.
  void orbit(float dx_px, float dy_px);
  void pan(float dx_px, float dy_px, const Viewport& viewport);
  void zoom(float wheel_clicks);

  // Frames a pit of the given half width (unit: m) and fill height (unit: m) from a
  // three-quarter view.
  void frame_pit(float half_width, float fill_height);
  // Frames a character of the given height (unit: m) standing at root, from its front left,
  // close enough to see it move and with the pit around it.
  void frame_character(const Vec3& root, float height);
};

// Gravity that follows the camera: the same magnitude, along the camera's down direction.
Vec3 gravity_from_camera(const OrbitCamera& camera, float magnitude_mps2);

}  // namespace ballpit
