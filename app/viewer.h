// The interactive app: a window, the session stepped in real time, the renderer, the HUD, and
// the controls (mouse orbits / pans / zooms the camera, Q/E roll it, keys steer the character,
// gravity can follow the camera's down direction). Returns when the window closes.
#pragma once

#include "app/camera.h"
#include "app/session.h"
#include "app/sphere_renderer.h"

namespace ballpit {

struct ViewerOptions {
  SessionOptions session;
  Viewport size{1600, 900};
  SphereMode sphere_mode = SphereMode::Impostor;
  int frames = 0;  // close after this many frames; 0: when the user closes the window
};

// Throws GlUnavailable when there is no display or no GL 4.5, before anything is simulated.
void run_viewer(const ViewerOptions& options);

}  // namespace ballpit
