// Frame time split into simulation and rendering, at several sphere counts, for both sphere
// paths (ray-cast impostors and the icosphere mesh). Each frame is what the app does: one
// physics step, then a full render of the pit and every sphere (the upload of the step's
// columns included), finished (glFinish) so a software rasteriser's work is counted; both
// paths render every frame's state, so they are compared on the same balls. Runs
// offscreen (EGL), so it works on a server with no display; prints a table, and with --jsonl
// writes one JSON line per (N, path) for scripts/profile_render.sh.
//
//   bench_render --spheres 10000,100000,1000000 --frames 20,8,3 --jsonl render.jsonl
#include <CLI/CLI.hpp>
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/camera.h"
#include "app/gl_context.h"
#include "app/offscreen_context.h"
#include "app/render_target.h"
#include "app/renderer.h"
#include "app/session.h"
#include "engine/atomic_file.h"
#include "engine/error.h"

using namespace ballpit;
using Clock = std::chrono::steady_clock;

namespace {

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Frame time split into simulation and rendering, impostors against meshes"};
  std::vector<std::size_t> counts = {10000, 100000, 1000000};
  std::vector<int> frames = {20, 8, 3};
  int warmup = 2;
  int threads = 0;
  int width = 1280, height = 720;
  std::string jsonl;
  app.add_option("--spheres", counts, "Sphere counts (pour scene)")->delimiter(',')->capture_default_str();
  app.add_option("--frames", frames, "Measured frames per count (one per count, or one for all)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--warmup", warmup, "Unmeasured frames first (fills the stream's regions)")->capture_default_str();
  app.add_option("--threads", threads, "Worker threads (0: all)")->capture_default_str();
  app.add_option("--width", width)->capture_default_str();
  app.add_option("--height", height)->capture_default_str();
  app.add_option("--jsonl", jsonl, "Write the results as JSON lines to this file");
  CLI11_PARSE(app, argc, argv);

  std::string lines;
  try {
    OffscreenContext context;
    std::fprintf(stderr, "[bench_render] %s, %dx%d\n", context.description().c_str(), width, height);
    std::printf("%10s %-9s %8s %12s %12s %12s %12s %12s\n", "spheres", "path", "frames", "sim ms", "render ms",
                "upload ms", "gpu-timer ms", "frame ms");
    for (std::size_t c = 0; c < counts.size(); ++c) {
      const int measured = frames[std::min(c, frames.size() - 1)];
      SessionOptions options;
      options.scene = "pour";
      options.spheres = counts[c];
      options.threads = threads;
      Session session(options);
      RenderTarget target(width, height);
      const OrbitCamera camera = default_camera(session);
      // Both paths draw every frame's state, one after the other, each with its own renderer
      // (and instance stream, so each uploads the step): on a shared machine a load spike
      // then hits both paths alike.
      struct Path {
        SphereMode mode;
        std::unique_ptr<Renderer> renderer;
        std::vector<double> render, upload, gpu;
      };
      Path paths[2] = {{SphereMode::Impostor, std::make_unique<Renderer>(), {}, {}, {}},
                       {SphereMode::Mesh, std::make_unique<Renderer>(), {}, {}, {}}};
      std::vector<double> sim;
      for (int f = 0; f < warmup + measured; ++f) {
        // One step of real time, as the app's loop takes it: the loop steps once, and the
        // renderer uploads everything interpolation needs (previous positions by entity too).
        const auto t0 = Clock::now();
        if (session.advance(session.world().step()) != 1) throw Error("the fixed-step loop did not take one step");
        const auto t1 = Clock::now();
        if (f >= warmup) sim.push_back(ms(t0, t1));
        for (Path& p : paths) {
          RenderSettings settings;
          settings.sphere_mode = p.mode;
          const auto r0 = Clock::now();
          target.bind();
          p.renderer->render(session, camera, target.viewport(), settings);
          p.renderer->end_frame();
          glFinish();
          const auto r1 = Clock::now();
          p.renderer->gpu_timer().collect_all();
          if (f < warmup) continue;
          p.render.push_back(ms(r0, r1));
          p.upload.push_back(p.renderer->upload_ms());
          p.gpu.push_back(p.renderer->gpu_ms());
        }
      }
      const double sim_ms = median(sim);
      for (const Path& p : paths) {
        const double render_ms = median(p.render);
        std::printf("%10zu %-9s %8d %12.2f %12.2f %12.2f %12.2f %12.2f\n", counts[c],
                    std::string(to_string(p.mode)).c_str(), measured, sim_ms, render_ms, median(p.upload),
                    median(p.gpu), sim_ms + render_ms);
        std::fflush(stdout);
        nlohmann::ordered_json j;
        j["spheres"] = counts[c];
        j["path"] = std::string(to_string(p.mode));
        j["triangles_per_sphere"] = p.renderer->spheres().triangles_per_sphere(p.mode);
        j["threads"] = session.threads();
        j["width"] = width;
        j["height"] = height;
        j["frames"] = measured;
        j["sim_ms_median"] = sim_ms;
        j["sim_ms_mean"] = mean(sim);
        j["render_ms_median"] = render_ms;
        j["render_ms_mean"] = mean(p.render);
        j["upload_ms_median"] = median(p.upload);
        j["gpu_timer_ms_median"] = median(p.gpu);
        j["renderer"] = context.description();
        lines += j.dump() + "\n";
      }
    }
    if (!jsonl.empty()) write_file_atomically(jsonl, lines);
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_render: %s\n", e.what());
    return 2;
  }
  return 0;
}
