#include "app/imgui_layer.h"

#include <epoxy/gl.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "app/gl_context.h"

namespace ballpit {

ImGuiLayer::ImGuiLayer(GLFWwindow* window) : has_window_(window != nullptr) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini left in the working directory
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 4.0f;
  style.FrameRounding = 3.0f;
  style.Colors[ImGuiCol_WindowBg].w = 0.82f;
  if (window && !ImGui_ImplGlfw_InitForOpenGL(window, true)) {
    ImGui::DestroyContext();
    throw GlUnavailable("Dear ImGui: the GLFW backend failed to initialise");
  }
  // The backend loads GL entry points through its own loader (libGL.so.1); it fails only
  // where no desktop GL library is installed.
  if (!ImGui_ImplOpenGL3_Init("#version 450 core")) {
    if (window) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    throw GlUnavailable("Dear ImGui: the OpenGL3 backend could not load OpenGL (is libGL.so.1 installed?)");
  }
}

ImGuiLayer::~ImGuiLayer() {
  ImGui_ImplOpenGL3_Shutdown();
  if (has_window_) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void ImGuiLayer::new_frame(const Viewport& viewport, float dt_s) {
  ImGui_ImplOpenGL3_NewFrame();
  if (has_window_) {
    ImGui_ImplGlfw_NewFrame();
  } else {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(viewport.width), static_cast<float>(viewport.height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    io.DeltaTime = dt_s > 0.0f ? dt_s : 1.0f / 60.0f;
  }
  ImGui::NewFrame();
}

void ImGuiLayer::render() {
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

bool ImGuiLayer::wants_mouse() const { return ImGui::GetIO().WantCaptureMouse; }
bool ImGuiLayer::wants_keyboard() const { return ImGui::GetIO().WantCaptureKeyboard; }

}  // namespace ballpit
