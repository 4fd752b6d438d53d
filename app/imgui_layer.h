// Owns the Dear ImGui context and its OpenGL3 renderer backend; with a window it also runs the
// GLFW platform backend (mouse, keyboard, clipboard). Offscreen there is no platform: the
// caller sets the display size and time step, which is all a screenshot of the HUD needs.
#pragma once

#include "app/camera.h"

struct GLFWwindow;

namespace ballpit {

class ImGuiLayer {
 public:
  // window may be null (offscreen). Throws GlUnavailable if the backend cannot load GL.
  explicit ImGuiLayer(GLFWwindow* window);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void new_frame(const Viewport& viewport, float dt_s);
  void render();
  // True when the pointer or keyboard is over a widget, so the camera and character ignore it.
  bool wants_mouse() const;
  bool wants_keyboard() const;

 private:
  bool has_window_;
};

}  // namespace ballpit
