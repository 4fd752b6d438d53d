#include "app/window.h"

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "app/gl_context.h"

namespace ballpit {

namespace {

std::string last_glfw_error;

void on_glfw_error(int code, const char* message) {
  last_glfw_error = message ? message : "unknown error " + std::to_string(code);
}

void on_scroll(GLFWwindow* w, double, double dy) {
  // The scroll total lives in the Window; ImGui's backend chains to this callback.
  auto* self = static_cast<float*>(glfwGetWindowUserPointer(w));
  if (self) *self += static_cast<float>(dy);
}

}  // namespace

Window::Window(int width, int height, const std::string& title) {
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit())
    throw GlUnavailable("no display: GLFW cannot initialise (" + last_glfw_error +
                        "). Run with a display, under xvfb-run, or use --screenshot FILE.png for offscreen rendering.");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    std::string why = last_glfw_error;
    glfwTerminate();
    throw GlUnavailable("cannot create a window with an OpenGL 4.5 core context (" + why +
                        "). The driver may be too old; Mesa's llvmpipe (LIBGL_ALWAYS_SOFTWARE=1) provides 4.5.");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  glfwSetWindowUserPointer(window_, &scroll_);
  glfwSetScrollCallback(window_, on_scroll);
  try {
    description_ = "GLFW window, " + require_gl45("the window's context").describe();
  } catch (...) {
    glfwDestroyWindow(window_);
    glfwTerminate();
    throw;
  }
}

Window::~Window() {
  glfwDestroyWindow(window_);
  glfwTerminate();
}

bool Window::should_close() const { return glfwWindowShouldClose(window_); }
void Window::close() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void Window::swap() { glfwSwapBuffers(window_); }
void Window::poll() { glfwPollEvents(); }

Viewport Window::framebuffer() const {
  Viewport v;
  glfwGetFramebufferSize(window_, &v.width, &v.height);
  return v;
}

bool Window::key_down(int key) const { return glfwGetKey(window_, key) == GLFW_PRESS; }
bool Window::mouse_down(int button) const { return glfwGetMouseButton(window_, button) == GLFW_PRESS; }

Vec2 Window::cursor() const {
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  return Vec2(static_cast<float>(x), static_cast<float>(y));
}

float Window::take_scroll() {
  float s = scroll_;
  scroll_ = 0.0f;
  return s;
}

}  // namespace ballpit
