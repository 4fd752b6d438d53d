// What every OpenGL context the app makes must offer, checked once after it is made current:
// a 4.5 core context (direct state access, buffer storage, conservative depth). A context
// without it is refused here with the driver's own strings, so nothing later fails obscurely.
// Decision: both the window and the offscreen context go through require_gl45, so the app,
// the screenshot path and the tests reject the same drivers with the same message.
#pragma once

#include <string>

#include "engine/error.h"

namespace ballpit {

// The environment cannot give the app what it needs (no display, no EGL, no GL 4.5). main
// catches it to fall back to offscreen rendering, or to explain and exit.
class GlUnavailable : public Error {
 public:
  using Error::Error;
};

struct GlInfo {
  std::string vendor;
  std::string renderer;
  std::string version;
  int version_number = 0;  // major * 10 + minor
  std::string describe() const { return renderer + " (OpenGL " + version + ", " + vendor + ")"; }
};

// Reads the current context's strings and throws GlUnavailable naming `how` (how the context
// was made) when it is not 4.5 core.
GlInfo require_gl45(const std::string& how);

// Whether the current context rasterises on the CPU (Mesa's llvmpipe or softpipe). There the
// GPU timer measures nothing useful, and finishing each frame is what counts its cost.
bool is_software_renderer();

// Routes driver errors (KHR_debug, core in 4.3) to stderr; performance notes are dropped.
void install_gl_debug_output();

}  // namespace ballpit
