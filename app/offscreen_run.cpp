#include "app/offscreen_run.h"

#include <epoxy/gl.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "app/gl_context.h"
#include "app/headless_run.h"
#include "app/hud.h"
#include "app/imgui_layer.h"
#include "app/offscreen_context.h"
#include "app/render_target.h"
#include "app/renderer.h"
#include "engine/error.h"
#include "engine/profiler.h"

namespace ballpit {

namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace

nlohmann::ordered_json run_offscreen(const OffscreenOptions& o) {
  if (o.frames < 1) throw Error("--frames must be >= 1");
  if (o.screenshot.empty()) throw Error("--screenshot needs a file name");
  check_output_path("--screenshot", o.screenshot);  // before the frames, not after them

  // The GL objects, or the reason there are none (only allowed when rendering is optional).
  std::unique_ptr<OffscreenContext> context;
  std::string no_gl;
  try {
    context = std::make_unique<OffscreenContext>();
  } catch (const GlUnavailable& e) {
    if (!o.rendering_optional) throw;
    no_gl = e.what();
    std::fprintf(stderr, "ballpit: %s\nballpit: simulating without rendering; no screenshot will be written\n",
                 e.what());
  }
  Session session(o.session);
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<RenderTarget> target;
  std::unique_ptr<ImGuiLayer> imgui;
  if (context) {
    renderer = std::make_unique<Renderer>();
    target = std::make_unique<RenderTarget>(o.size.width, o.size.height, o.samples);
    if (o.ui) imgui = std::make_unique<ImGuiLayer>(nullptr);
  }

  OrbitCamera camera = default_camera(session);
  if (o.ui) camera.lens_shift = hud_lens_shift(o.size.width);
  RenderSettings settings;
  settings.sphere_mode = o.sphere_mode;
  ViewState view;
  view.sphere_mode = o.sphere_mode;
  view.follow_character = session.has_character();
  Profiler frames;
  std::vector<double> step_ms, render_ms;
  step_ms.reserve(static_cast<std::size_t>(o.frames));
  render_ms.reserve(static_cast<std::size_t>(o.frames));

  for (int i = 0; i < o.frames; ++i) {
    frames.begin_frame();
    const auto t0 = Clock::now();
    session.single_step();
    const auto t1 = Clock::now();
    frames.record("simulation", t0, t1);
    step_ms.push_back(ms_between(t0, t1));
    if (!renderer) {
      frames.end_frame();
      continue;
    }

    target->bind();
    renderer->render(session, camera, target->viewport(), settings);
    // Offscreen there is no swap to pace the frame: finishing makes the render time include
    // the rasteriser's work (llvmpipe's threads), not just the submission.
    glFinish();
    const auto t2 = Clock::now();
    frames.record("render", t1, t2);
    render_ms.push_back(ms_between(t1, t2));

    if (imgui) {
      imgui->new_frame(target->viewport(), 1.0f / 60.0f);
      FrameStats stats;
      stats.fps = 1000.0 / std::max(1e-3, ms_between(t0, t2));
      stats.gpu_ms = is_software_renderer() ? -1.0 : renderer->gpu_ms();
      stats.steps_last_frame = 1;
      draw_hud(session, view, frames, stats);
      imgui->render();
      glFinish();
      frames.record("ui", t2, Clock::now());
    }
    renderer->end_frame();
    frames.end_frame();
  }

  Image image;
  if (target) {
    image = target->read();
    write_png(o.screenshot, image);
  }

  if (o.print_table) {
    std::fprintf(stderr, "%s", session.scheduler().profiler().table().c_str());
    std::fprintf(stderr, "per frame:\n%s", frames.table().c_str());
    if (context)
      std::fprintf(stderr, "[ballpit] %s; wrote %s (%dx%d)\n", context->description().c_str(), o.screenshot.c_str(),
                   image.width, image.height);
  }
  nlohmann::ordered_json report = step_report(session.options().scene, session.world(), session.threads(), step_ms);
  report["frames"] = o.frames;
  if (context) {
    report["sphere_mode"] = std::string(to_string(o.sphere_mode));
    report["render_ms_mean"] = std::round(mean(render_ms) * 1e4) / 1e4;
    report["render_ms_median"] = std::round(median(render_ms) * 1e4) / 1e4;
    report["width"] = image.width;
    report["height"] = image.height;
    report["screenshot"] = o.screenshot;
  } else {
    report["screenshot_error"] = no_gl;
  }
  return report;
}

}  // namespace ballpit
