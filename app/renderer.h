// One frame of the scene: fills the per-frame uniforms from the camera, then draws the pit,
// the spheres and (when the session has one) the character and its colliders into whatever
// framebuffer is bound: a window's, or an offscreen target for screenshots and tests.
// Decision: the renderer only reads the session; it never steps or edits it, so the app, the
// screenshot path and the tests all draw the same thing from the same state.
#pragma once

#include "app/camera.h"
#include "app/character_renderer.h"
#include "app/collider_renderer.h"
#include "app/gl_objects.h"
#include "app/gpu_timer.h"
#include "app/pit_renderer.h"
#include "app/session.h"
#include "app/sphere_renderer.h"

namespace ballpit {

struct RenderSettings {
  SphereMode sphere_mode = SphereMode::Impostor;
  bool draw_pit = true;
  bool draw_spheres = true;
  bool draw_character = true;
  bool show_colliders = false;  // the joint colliders, translucent, with the character as a ghost
  Vec3 clear_color = Vec3(0.63f, 0.70f, 0.78f);  // sRGB sky
};

class Renderer {
 public:
  // Compiles every program; throws ShaderError with the log if one fails.
  Renderer();

  void render(const Session& session, const OrbitCamera& camera, const Viewport& viewport,
              const RenderSettings& settings);
  // Fences this frame's instance data; call after everything that reads it (end of frame).
  void end_frame() { spheres_.end_frame(); }

  double gpu_ms() const { return gpu_timer_.last_ms(); }
  // CPU time of the last frame's sphere upload (0 when the columns had not changed) (unit: ms).
  double upload_ms() const { return upload_ms_; }
  GpuTimer& gpu_timer() { return gpu_timer_; }
  const SphereRenderer& spheres() const { return spheres_; }

 private:
  GlBuffer frame_uniforms_;
  SphereRenderer spheres_;
  PitRenderer pit_;
  CharacterRenderer character_;
  ColliderRenderer colliders_;
  GpuTimer gpu_timer_;
  double upload_ms_ = 0.0;
};

}  // namespace ballpit
