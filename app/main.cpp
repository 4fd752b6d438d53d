// ballpit: the command line. With no subcommand it opens the interactive pit (or, with
// --screenshot, renders offscreen); `ballpit run` is the headless runner; `ballpit make-marine
// FILE.glb` writes the built-in marine as glTF for other tools. See --help.
#include <CLI/CLI.hpp>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "app/gl_context.h"
#include "app/headless_run.h"
#include "app/offscreen_run.h"
#include "app/viewer.h"
#include "engine/error.h"
#include "engine/marine/marine.h"
#include "engine/model_export.h"
#include "engine/settings.h"

namespace {

// Where `ballpit` with no arguments writes its screenshot when there is no display.
constexpr const char* kFallbackScreenshot = "ballpit.png";

// A count of at least one. (CLI::PositiveNumber's refusal spelt out the largest double, all
// 309 digits of it, as the end of its range.)
const CLI::Validator kPositiveCount(
    [](std::string& text) {
      long long value = 0;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
      const std::string refusal = "expected a whole number of at least 1, got '" + text + "'";
      if (error == std::errc::result_out_of_range && !text.starts_with('-')) return refusal + ", which is far too large";
      if (error != std::errc{} || end != text.data() + text.size() || value < 1) return refusal;
      return std::string{};
    },
    "POSITIVE");

}  // namespace

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Blocks of 128 KiB and more straight from mmap, handed back to the system when freed. glibc
  // starts there but raises the threshold to each mmapped block freed (up to 32 MiB): after the
  // first contact lists and batches outgrew their buffers, theirs came from the heap, and the
  // freed ones stayed resident beside the new. 100k pour, 60 steps: peak RSS 133 -> 107 MB, the
  // same state hash (issue 42). The library leaves the allocator alone: this is the program's.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
  CLI::App app{"ballpit: a multithreaded ball-pit physics engine.\n"
               "With no subcommand: the interactive pit (or offscreen with --screenshot)."};
  app.require_subcommand(0, 1);

  ballpit::OffscreenOptions view;
  std::string sphere_mode = "impostor";
  std::string collider_kind = "capsules";
  bool screenshot_given = false;
  app.add_option("--scene", view.session.scene,
                 "'play' (the pit with the character), 'pour' (SCENES.md, balls only) or a scene file (.json, see scenes/)")
      ->capture_default_str()
      ->check([](const std::string& s) {
        return s == "play" || s == "pour" || s.ends_with(".json") ? std::string{} : "expected play, pour or a .json scene file";
      });
  app.add_option("--set", view.session.set,
                 "With a scene file: override one of its fields, e.g. --set character.control=player (repeatable)");
  app.add_option("--spheres", view.session.spheres,
                 "Number of balls (default: the scene's; play 40000, pour 10000; a file's first population)")
      ->check(kPositiveCount);
  CLI::Option* colliders = app.add_option("--colliders", collider_kind, "Joint colliders: 'capsules' or 'spheres'")
                               ->capture_default_str()
                               ->check(CLI::IsMember({"capsules", "spheres"}));
  app.add_option("--threads", view.session.threads, "Worker threads (0: all hardware threads)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  app.add_option("--renderer", sphere_mode, "Spheres as 'impostor' (ray-cast, 2 triangles) or 'mesh' (icosphere)")
      ->capture_default_str()
      ->check(CLI::IsMember({"impostor", "mesh"}));
  app.add_option("--width", view.size.width, "Window or image width (pixels)")->capture_default_str()->check(CLI::Range(16, 16384));
  app.add_option("--height", view.size.height, "Window or image height (pixels)")->capture_default_str()->check(CLI::Range(16, 16384));
  CLI::Option* shot = app.add_option("--screenshot", view.screenshot,
                                     "Render offscreen (no window, no X needed) and write the final frame to this PNG");
  CLI::Option* frames = app.add_option("--frames", view.frames,
                                       "With --screenshot: frames before the shot (one 1/60 s step each); "
                                       "with a window: close after this many frames")
                            ->capture_default_str()
                            ->check(kPositiveCount);
  app.add_option("--samples", view.samples, "Multisamples for the screenshot")->capture_default_str()->check(CLI::Range(1, 16));
  app.add_flag("!--no-ui", view.ui, "Leave the HUD out of the screenshot");

  ballpit::RunOptions run;
  bool headless = false;
  CLI::App* cmd = app.add_subcommand("run", "Run a scene headless and print its report");
  cmd->add_flag("--headless", headless, "No window at all (always the case for `run`; accepted for clarity)");
  cmd->add_option("--scene", run.scene, "Scene to run (pour, pit-character) or a scene file (.json, see scenes/)")
      ->capture_default_str();
  cmd->add_option("--spheres", run.spheres, "Number of spheres N")->capture_default_str()->check(kPositiveCount);
  cmd->add_option("--steps", run.steps, "Fixed steps to run (1/60 s each)")->capture_default_str()->check(kPositiveCount);
  cmd->add_option("--threads", run.threads, "Worker threads (OpenMP and scheduler)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  cmd->add_option("--trace", run.trace_path, "Write a Chrome trace (JSON, opens in Perfetto) to this file");
  cmd->add_option("--substeps", run.substeps, "Solver substeps per step (default: the scene's)")->check(CLI::Range(1, 64));
  cmd->add_option("--solve-sweeps", run.solve_sweeps,
                  "Gauss-Seidel sweeps of the solve pass per substep (default: the scene's; 3 substeps of 2 "
                  "sweeps hold piles better than 4 of 1 at about the same cost, and time impacts worse)")
      ->check(CLI::Range(1, ballpit::kMaxSolveSweeps));
  cmd->add_option("--tolerance", run.tolerance_r,
                  "Accuracy as an input: keep the deepest overlap after each step under P x the ball radius "
                  "(0 < P <= 1, e.g. 0.01) by choosing the substeps (1..32) every step, starting from --substeps "
                  "or the scene's; the report adds tolerance_r, max_step_penetration_r, steps_over_tolerance and "
                  "substeps_mean/min/max/final")
      ->check(CLI::Range(1e-6, 1.0));
  cmd->add_flag("--sleeping", run.sleeping, "Let settled spheres sleep (the canonical pour measures without)");
  cmd->add_flag("--naive", run.naive, "Reference all-pairs narrowphase instead of the grid (O(N^2))");
  cmd->add_option("--set", run.set,
                  "Override a scene field, e.g. --set solver.substeps=4 or --set populations.0.radius=0.05 "
                  "(repeatable; works with --scene pour, pit-character or a .json file)");
  cmd->add_option("--load", run.load_path, "Resume from this snapshot instead of building the scene");
  cmd->add_option("--save", run.save_path,
                  "Save a snapshot here after the run (and the last good state if the NaN guard stops it)");
  cmd->add_flag("!--no-progress", run.progress, "Do not print progress lines on stderr");
  cmd->add_flag("!--no-table", run.print_table, "Do not print the per-system table on stderr");

  std::string marine_path;
  CLI::App* marine_cmd = app.add_subcommand("make-marine", "Write the built-in marine (builtin:marine) as glTF 2.0");
  marine_cmd->add_option("file", marine_path, "Output file: FILE.glb (binary) or FILE.gltf (with FILE.bin beside it)")
      ->required();

  CLI11_PARSE(app, argc, argv);
  if (run.scene.ends_with(".json") || !run.set.empty()) {
    // The scene's own spheres and steps apply unless given on the command line (--spheres sets
    // the first population's count).
    if (cmd->get_option("--spheres")->count()) run.set.push_back("populations.0.count=" + std::to_string(run.spheres));
    if (cmd->get_option("--steps")->count()) run.set.push_back("steps=" + std::to_string(run.steps));
  }
  screenshot_given = shot->count() > 0;

  try {
    if (app.got_subcommand(marine_cmd)) {
      // The folder is checked here so the message names it; the export names the file.
      const std::filesystem::path folder = std::filesystem::path(marine_path).parent_path();
      std::error_code ec;
      if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
        throw ballpit::Error("make-marine: the folder '" + folder.string() + "' of '" + marine_path + "' does not exist");
      ballpit::export_model_gltf(ballpit::marine::make_marine(), marine_path);
      nlohmann::ordered_json report = {{"model", ballpit::marine::kModelName}, {"file", marine_path}};
      std::cout << report.dump() << std::endl;
      return 0;
    }
    if (app.got_subcommand(cmd)) {
      nlohmann::ordered_json report = ballpit::run_headless(run);
      std::cout << report.dump() << std::endl;
      return 0;
    }
    view.sphere_mode = ballpit::sphere_mode_from_string(sphere_mode);
    if (colliders->count()) {
      view.session.colliders = collider_kind == "spheres" ? ballpit::ColliderKind::Spheres : ballpit::ColliderKind::Capsules;
      // A scene file names its character's colliders; the flag overrides that field.
      if (view.session.uses_scene_file()) view.session.set.push_back("character.colliders=" + collider_kind);
    }
    if (screenshot_given) {
      std::cout << ballpit::run_offscreen(view).dump() << std::endl;
      return 0;
    }
    try {
      ballpit::ViewerOptions viewer;
      viewer.session = view.session;
      viewer.sphere_mode = view.sphere_mode;
      if (frames->count()) viewer.frames = view.frames;
      if (app.get_option("--width")->count() || app.get_option("--height")->count()) viewer.size = view.size;
      ballpit::run_viewer(viewer);
      return 0;
    } catch (const ballpit::GlUnavailable& e) {
      // No display (a server, a container, CI): still show what the engine does.
      std::fprintf(stderr, "ballpit: %s\nballpit: no interactive window, so running %d frames offscreen instead: "
                           "per-system report below, screenshot in %s\n",
                   e.what(), view.frames, kFallbackScreenshot);
      view.screenshot = kFallbackScreenshot;
      view.rendering_optional = true;
      nlohmann::ordered_json report = ballpit::run_offscreen(view);
      std::cout << report.dump() << std::endl;
      return report.contains("screenshot") ? 0 : 1;
    }
  } catch (const ballpit::Error& e) {
    std::fprintf(stderr, "ballpit: %s\n", e.what());
    return 2;
  }
}
