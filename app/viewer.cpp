#include "app/viewer.h"

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>

#include "app/controls.h"
#include "app/gl_context.h"
#include "app/hud.h"
#include "app/image.h"
#include "app/imgui_layer.h"
#include "app/render_target.h"
#include "app/renderer.h"
#include "app/window.h"
#include "engine/error.h"
#include "engine/profiler.h"

namespace ballpit {

namespace {

using Clock = std::chrono::steady_clock;

// Profilers keep every frame; past ten minutes at 60 Hz the history is dropped so a session
// left running does not grow without bound (the HUD only shows the last two seconds).
constexpr std::size_t kProfilerFrames = 36000;

std::string screenshot_name() {
  char name[64];
  std::time_t now = std::time(nullptr);
  std::strftime(name, sizeof name, "ballpit-%Y%m%d-%H%M%S.png", std::localtime(&now));
  return name;
}

// Gravity follows the camera only when it has turned by more than this: setting gravity wakes
// every sleeping ball, so a still camera must not keep re-setting it (unit: rad).
constexpr float kGravityTurnThreshold = 0.002f;

void update_gravity(World& world, const OrbitCamera& camera, const ViewState& view, float magnitude) {
  Vec3 want = view.gravity_follows_camera ? gravity_from_camera(camera, magnitude) : Vec3(0.0f, -magnitude, 0.0f);
  Vec3 have = world.gravity();
  float cos_angle = want.normalized().dot(have.normalized());
  if (std::acos(std::clamp(cos_angle, -1.0f, 1.0f)) > kGravityTurnThreshold) world.set_gravity(want);
}

// Follow mode: the camera's target eases towards the character's chest, so the player can
// still orbit and zoom around it; the easing (time constant 0.25 s) hides the step rate.
void follow(OrbitCamera& camera, const Session& session, double dt) {
  const CharacterSetup& setup = session.world().characters.setup(0);
  const float height = setup.model->bind_height() * setup.scale;  // (unit: m)
  const Vec3 chest = session.character_position() + Vec3(0.0f, 0.45f * height, 0.0f);
  const float k = 1.0f - std::exp(-static_cast<float>(dt) / 0.25f);
  camera.target += k * (chest - camera.target);
}

class MouseDrag {
 public:
  void update(Window& window, OrbitCamera& camera, const Viewport& viewport, bool ui_has_mouse) {
    Vec2 now = window.cursor();
    Vec2 d = now - last_;
    last_ = now;
    if (ui_has_mouse) return;
    if (window.mouse_down(GLFW_MOUSE_BUTTON_LEFT)) camera.orbit(d.x(), d.y());
    if (window.mouse_down(GLFW_MOUSE_BUTTON_RIGHT) || window.mouse_down(GLFW_MOUSE_BUTTON_MIDDLE))
      camera.pan(d.x(), d.y(), viewport);
    camera.zoom(window.take_scroll());
  }

 private:
  Vec2 last_ = Vec2::Zero();
};

}  // namespace

void run_viewer(const ViewerOptions& o) {
  Window window(o.size.width, o.size.height, "ballpit");
  std::fprintf(stderr, "[ballpit] %s\n", window.description().c_str());
  // A software rasteriser draws on the CPU when the frame is flushed; finishing each frame
  // puts that work in the "render" bar instead of hiding it in the next swap. On a GPU the
  // frame is left to run ahead, and the GPU timer reports its cost.
  const bool software = is_software_renderer();
  Session session(o.session);
  Renderer renderer;
  ImGuiLayer imgui(window.handle());

  OrbitCamera camera = default_camera(session);
  const float gravity_magnitude = session.world().gravity().norm();
  ViewState view;
  view.sphere_mode = o.sphere_mode;
  view.follow_character = session.has_character();
  RenderSettings settings;
  Profiler frames;
  MouseDrag drag;
  FrameStats stats;
  bool pause_key_was_down = false, step_key_was_down = false, follow_key_was_down = false;
  bool shot_key_was_down = false;
  std::size_t frame_count = 0;

  auto last = Clock::now();
  while (!window.should_close()) {
    window.poll();
    const auto t0 = Clock::now();
    const double dt = std::chrono::duration<double>(t0 - last).count();
    last = t0;
    frames.begin_frame();
    const Viewport viewport = window.framebuffer();
    camera.lens_shift = hud_lens_shift(viewport.width);

    drag.update(window, camera, viewport, imgui.wants_mouse());
    KeyState keys;
    if (!imgui.wants_keyboard()) {
      keys.forward = window.key_down(GLFW_KEY_W) || window.key_down(GLFW_KEY_UP);
      keys.back = window.key_down(GLFW_KEY_S) || window.key_down(GLFW_KEY_DOWN);
      keys.left = window.key_down(GLFW_KEY_A) || window.key_down(GLFW_KEY_LEFT);
      keys.right = window.key_down(GLFW_KEY_D) || window.key_down(GLFW_KEY_RIGHT);
      keys.run = window.key_down(GLFW_KEY_LEFT_SHIFT) || window.key_down(GLFW_KEY_RIGHT_SHIFT);
      keys.jump = window.key_down(GLFW_KEY_SPACE);
      keys.kick = window.key_down(GLFW_KEY_K);
      bool follow_down = window.key_down(GLFW_KEY_F);
      if (follow_down && !follow_key_was_down) view.follow_character = !view.follow_character;
      follow_key_was_down = follow_down;
      const float roll_speed = 1.2f;  // (unit: rad/s)
      if (window.key_down(GLFW_KEY_Q)) camera.roll += roll_speed * static_cast<float>(dt);
      if (window.key_down(GLFW_KEY_E)) camera.roll -= roll_speed * static_cast<float>(dt);
      if (window.key_down(GLFW_KEY_ESCAPE)) window.close();
      bool pause_down = window.key_down(GLFW_KEY_P);
      if (pause_down && !pause_key_was_down) session.paused = !session.paused;
      pause_key_was_down = pause_down;
      bool step_down = window.key_down(GLFW_KEY_N);
      if (step_down && !step_key_was_down) session.single_step();
      step_key_was_down = step_down;
      bool shot_down = window.key_down(GLFW_KEY_F12);
      if (shot_down && !shot_key_was_down) view.screenshot_requested = true;
      shot_key_was_down = shot_down;
    }
    if (view.reset_camera) {
      camera = default_camera(session);
      view.reset_camera = false;
    }
    session.set_character_input(controller_input(keys));
    update_gravity(session.world(), camera, view, gravity_magnitude);

    stats.steps_last_frame = session.advance(dt);
    if (view.follow_character && session.has_character()) follow(camera, session, dt);
    const auto t1 = Clock::now();
    frames.record("simulation", t0, t1);

    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, viewport.width, viewport.height);
    settings.sphere_mode = view.sphere_mode;
    settings.show_colliders = view.show_colliders;
    renderer.render(session, camera, viewport, settings);
    if (software) glFinish();
    const auto t2 = Clock::now();
    frames.record("render", t1, t2);

    imgui.new_frame(viewport, static_cast<float>(dt));
    // Smoothed over about ten frames, so the number can be read.
    if (dt > 0.0) stats.fps = stats.fps > 0.0 ? 0.9 * stats.fps + 0.1 / dt : 1.0 / dt;
    stats.gpu_ms = software ? -1.0 : renderer.gpu_ms();
    draw_hud(session, view, frames, stats);
    imgui.render();
    frames.record("ui", t2, Clock::now());

    if (view.screenshot_requested) {
      view.screenshot_requested = false;
      std::string path = screenshot_name();
      try {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        glReadBuffer(GL_BACK);
        write_png(path, read_framebuffer(viewport.width, viewport.height));
        view.status = "wrote " + path;
      } catch (const Error& e) {
        view.status = e.what();
      }
    }
    renderer.end_frame();
    window.swap();
    frames.end_frame();
    if (o.frames > 0 && static_cast<int>(frame_count + 1) >= o.frames) window.close();
    if (++frame_count % kProfilerFrames == 0) {
      frames.reset();
      session.scheduler().profiler().reset();
    }
  }
}

}  // namespace ballpit
