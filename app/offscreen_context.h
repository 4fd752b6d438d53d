// An OpenGL 4.5 core context with no window and no X server: EGL on Mesa's surfaceless
// platform (llvmpipe, or a GPU's render node), else EGL's device platform (NVIDIA's headless
// driver). Screenshots, tests and the render benchmark draw into framebuffer objects in it.
// Decision: the context is current on the creating thread for its whole life; callers draw
// from that thread only.
#pragma once

#include <string>

namespace ballpit {

class OffscreenContext {
 public:
  // Throws GlUnavailable explaining which EGL step failed (with the EGL error code).
  OffscreenContext();
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  void make_current();
  // "EGL surfaceless" or "EGL device", plus the GL renderer string.
  const std::string& description() const { return description_; }

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string description_;
};

}  // namespace ballpit
