#include "app/hud.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "app/session.h"
#include "engine/error.h"
#include "engine/profiler.h"
#include "engine/world.h"

namespace ballpit {

namespace {

// Last 2 s of 60 Hz steps or frames: long enough to steady the bars, short enough to follow
// a change (pouring, switching the narrowphase) within a couple of seconds.
constexpr std::size_t kWindow = 120;

void time_bar(const char* name, double ms, double scale_ms, ImVec4 color) {
  char label[96];
  std::snprintf(label, sizeof label, "%-18s %7.2f ms", name, ms);
  ImGui::PushStyleColor(ImGuiCol_PlotHistogram, color);
  ImGui::ProgressBar(static_cast<float>(std::clamp(ms / scale_ms, 0.0, 1.0)), ImVec2(-1.0f, 0.0f), label);
  ImGui::PopStyleColor();
}

void timing_section(const Session& session, const Profiler& frame_profiler, const FrameStats& stats) {
  std::vector<SystemStats> systems = session.scheduler().profiler().stats(kWindow);
  std::vector<SystemStats> frame = frame_profiler.stats(kWindow);
  double scale = 1000.0 / 60.0;  // a 60 Hz frame fills a bar
  for (const SystemStats& s : systems) scale = std::max(scale, s.median_ms);
  for (const SystemStats& s : frame) scale = std::max(scale, s.median_ms);

  ImGui::Text("%.1f frames/s   %d step%s last frame", stats.fps, stats.steps_last_frame,
              stats.steps_last_frame == 1 ? "" : "s");
  ImGui::TextDisabled("per physics step (median of %zu)", kWindow);
  double step_total = 0.0;
  for (const SystemStats& s : systems) {
    time_bar(s.name.c_str(), s.median_ms, scale, ImVec4(0.25f, 0.6f, 0.95f, 1.0f));
    step_total += s.median_ms;
  }
  time_bar("step total", step_total, scale, ImVec4(0.2f, 0.45f, 0.8f, 1.0f));
  ImGui::TextDisabled("per rendered frame");
  for (const SystemStats& s : frame) time_bar(s.name.c_str(), s.median_ms, scale, ImVec4(0.95f, 0.6f, 0.2f, 1.0f));
  if (stats.gpu_ms >= 0.0) time_bar("render (gpu)", stats.gpu_ms, scale, ImVec4(0.9f, 0.35f, 0.3f, 1.0f));
}

void sphere_section(Session& session, ViewState& view) {
  const World& world = session.world();
  if (world.solver.sleeping) {  // what the step pays for (systems/sleeping.h)
    auto asleep = world.spheres.asleep();
    const auto awake = static_cast<std::size_t>(std::count(asleep.begin(), asleep.end(), std::uint8_t{0}));
    ImGui::Text("%zu spheres, %zu awake", world.spheres.size(), awake);
  } else {
    ImGui::Text("%zu spheres", world.spheres.size());
  }
  ImGui::SetNextItemWidth(120.0f);
  ImGui::SliderInt("##pour", &view.pour_count, 100, 50000, "%d balls", ImGuiSliderFlags_Logarithmic);
  ImGui::SameLine();
  if (ImGui::Button("Pour more balls")) {
    session.pour(static_cast<std::size_t>(view.pour_count));
    view.status = "poured " + std::to_string(view.pour_count) + " balls";
  }
}

// Under the substeps slider, and under the solver section's header while it is closed: a pile
// sinking into itself is worth seeing without opening anything.
void substep_warning(Session& session) {
  const SolverSettings& solver = session.world().solver;
  if (const int needed = accurate_substeps(session.world().step(), solver.solve_sweeps); solver.substeps < needed)
    ImGui::TextColored(ImVec4(1.0f, 0.7f, 0.3f, 1.0f), "piles sink past 1%% of r below %d substeps", needed);
}

void solver_section(Session& session) {
  SolverSettings& solver = session.world().solver;
  int substeps = solver.substeps;
  if (ImGui::SliderInt("substeps", &substeps, 1, 16)) session.set_substeps(substeps);
  int sweeps = solver.solve_sweeps;
  if (ImGui::SliderInt("solve sweeps", &sweeps, 1, 4)) session.set_solve_sweeps(sweeps);
  substep_warning(session);
  float e = session.restitution();
  if (ImGui::SliderFloat("restitution", &e, 0.0f, 1.0f, "%.2f")) session.set_restitution(e);
  float mu = session.friction();
  if (ImGui::SliderFloat("friction", &mu, 0.0f, 1.5f, "%.2f")) session.set_friction(mu);
  int mode = solver.narrowphase == NarrowphaseMode::Grid ? 0 : 1;
  ImGui::Text("narrowphase");
  ImGui::SameLine();
  bool changed = ImGui::RadioButton("grid", &mode, 0);
  ImGui::SameLine();
  changed |= ImGui::RadioButton("naive O(N^2)", &mode, 1);
  if (changed) session.set_narrowphase(mode == 0 ? NarrowphaseMode::Grid : NarrowphaseMode::Naive);
  if (mode == 1 && session.world().spheres.size() > 20000)
    ImGui::TextColored(ImVec4(1.0f, 0.7f, 0.3f, 1.0f), "naive is quadratic: expect seconds per step");
}

void run_section(Session& session, ViewState& view) {
  ImGui::Checkbox("pause", &session.paused);
  ImGui::SameLine();
  if (ImGui::Button("single step")) session.single_step();
  ImGui::SameLine();
  if (ImGui::Button("reset")) {
    session.reset();
    view.reset_camera = true;
    view.status = "scene reset";
  }
  ImGui::SameLine();
  if (ImGui::Button("screenshot")) view.screenshot_requested = true;
}

void view_section(Session& session, ViewState& view) {
  int mode = view.sphere_mode == SphereMode::Impostor ? 0 : 1;
  ImGui::Text("spheres as");
  ImGui::SameLine();
  bool changed = ImGui::RadioButton("impostors", &mode, 0);
  ImGui::SameLine();
  changed |= ImGui::RadioButton("meshes", &mode, 1);
  if (changed) view.sphere_mode = mode == 0 ? SphereMode::Impostor : SphereMode::Mesh;
  ImGui::Checkbox("gravity follows camera down", &view.gravity_follows_camera);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Gravity points down the screen: roll (Q/E) or pitch the camera to slosh the balls");
  if (!session.has_character()) return;
  ImGui::Checkbox("follow character", &view.follow_character);
  ImGui::Checkbox("show colliders", &view.show_colliders);
  int kind = session.collider_kind() == ColliderKind::Capsules ? 1 : 0;
  ImGui::Text("colliders");
  ImGui::SameLine();
  bool kind_changed = ImGui::RadioButton("spheres at joints", &kind, 0);
  ImGui::SameLine();
  kind_changed |= ImGui::RadioButton("capsules", &kind, 1);
  if (kind_changed) session.set_collider_kind(kind == 1 ? ColliderKind::Capsules : ColliderKind::Spheres);
}

}  // namespace

void draw_hud(Session& session, ViewState& view, const Profiler& frame_profiler, const FrameStats& stats) {
  ImGui::SetNextWindowPos(ImVec2(8.0f, 8.0f), ImGuiCond_FirstUseEver);
  // Fixed width (the camera's lens shift assumes it), height fitted to the open sections.
  const float width = kHudWidth - 16.0f;
  ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0.0f), ImVec2(width, 1e6f));
  ImGui::Begin("ballpit", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  try {
    if (ImGui::CollapsingHeader("timings", ImGuiTreeNodeFlags_DefaultOpen)) timing_section(session, frame_profiler, stats);
    if (ImGui::CollapsingHeader("balls", ImGuiTreeNodeFlags_DefaultOpen)) sphere_section(session, view);
    if (ImGui::CollapsingHeader("solver")) solver_section(session);
    else substep_warning(session);
    if (ImGui::CollapsingHeader("run", ImGuiTreeNodeFlags_DefaultOpen)) run_section(session, view);
    if (ImGui::CollapsingHeader("view")) view_section(session, view);
  } catch (const Error& e) {
    view.status = e.what();  // a setting out of range: say so, keep running
  }
  if (!view.status.empty()) ImGui::TextWrapped("%s", view.status.c_str());
  ImGui::TextDisabled("drag: orbit  right drag: pan  wheel: zoom");
  ImGui::TextDisabled("Q/E: roll camera  P: pause  N: step  F12: shot");
  if (session.has_character()) {
    ImGui::TextDisabled("WASD/arrows: walk  Shift: run  F: follow");
    ImGui::TextDisabled("Space: jump  K: kick");
  }
  ImGui::End();
}

}  // namespace ballpit
