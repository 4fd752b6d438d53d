// The Dear ImGui panel: frame rate, each system's time per step as bars (from the scheduler's
// profiler) next to the frame's simulation, render and UI times (from the app's frame
// profiler), the sphere count and "pour more balls", solver settings, grid or naive
// narrowphase, pause / single step / reset, renderer and camera options, screenshot.
// Decision: the HUD edits the session only through its setters, and everything else it
// changes lives in ViewState, so the panel holds no state of its own between frames.
#pragma once

#include <string>

#include "app/sphere_renderer.h"

namespace ballpit {

class Profiler;
class Session;

// What the user chose that is not simulation state.
struct ViewState {
  SphereMode sphere_mode = SphereMode::Impostor;
  bool follow_character = false;
  bool gravity_follows_camera = false;
  bool show_colliders = false;
  int pour_count = 2000;
  bool screenshot_requested = false;
  bool reset_camera = false;
  std::string status;  // last action's outcome, shown under the buttons
};

struct FrameStats {
  double fps = 0.0;
  double gpu_ms = -1.0;  // negative: not measured yet
  int steps_last_frame = 0;
};

// The panel's width (unit: pixel); the camera's lens shift centres the scene beside it.
inline constexpr float kHudWidth = 350.0f;
inline float hud_lens_shift(int viewport_width) {
  return viewport_width > 0 ? kHudWidth / static_cast<float>(viewport_width) : 0.0f;
}

void draw_hud(Session& session, ViewState& view, const Profiler& frame_profiler, const FrameStats& stats);

}  // namespace ballpit
