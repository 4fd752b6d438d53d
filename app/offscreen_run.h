// `ballpit --screenshot FILE.png --frames N`: runs the app's frame loop with no window (EGL,
// no X server), one physics step per frame, draws every frame into an offscreen target, and
// writes the final frame as a PNG. Prints the per-system table (physics systems per step;
// simulation, render and UI per frame) and returns the report line (the headless runner's
// fields plus render times and the screenshot). Also what `ballpit` falls back to on a machine
// with no display.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "app/camera.h"
#include "app/session.h"
#include "app/sphere_renderer.h"

namespace ballpit {

struct OffscreenOptions {
  SessionOptions session;
  std::string screenshot = "ballpit.png";
  int frames = 300;                 // one fixed step (1/60 s) each
  Viewport size{1280, 720};
  int samples = 4;                  // multisampling of the final image
  SphereMode sphere_mode = SphereMode::Impostor;
  bool ui = true;                   // draw the HUD into the image
  bool print_table = true;          // per-system table on stderr
  // With no GL context at all, still simulate and report (report["screenshot_error"] says
  // why there is no image) instead of throwing: the no-display fallback of `ballpit`.
  bool rendering_optional = false;
};

// Throws GlUnavailable when no offscreen context can be made (unless rendering_optional),
// ballpit::Error for bad options or an unwritable screenshot path (nothing is left at the
// path then).
nlohmann::ordered_json run_offscreen(const OffscreenOptions& options);

}  // namespace ballpit
