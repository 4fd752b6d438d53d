// A desktop window with an OpenGL 4.5 core context, through GLFW. Construction fails with
// GlUnavailable (never a crash) when there is no display or the driver lacks GL 4.5, so the
// caller can fall back to offscreen rendering.
#pragma once

#include <string>

#include "app/camera.h"

struct GLFWwindow;

namespace ballpit {

class Window {
 public:
  Window(int width, int height, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }
  bool should_close() const;
  void close();
  void swap();
  void poll();
  Viewport framebuffer() const;
  bool key_down(int glfw_key) const;
  bool mouse_down(int glfw_button) const;
  Vec2 cursor() const;
  // Wheel clicks since the last call.
  float take_scroll();
  const std::string& description() const { return description_; }

 private:
  GLFWwindow* window_ = nullptr;
  std::string description_;
  float scroll_ = 0.0f;
};

}  // namespace ballpit
