// The live simulation behind the app: the world, its scheduler and fixed-step loop, the scene
// it was built from, and the controls the UI changes at run time (pause, single step, reset,
// pour more balls, solver settings, narrowphase). It knows nothing about OpenGL; the renderer
// reads it through RenderState.
// Decision: render state is versioned. The renderer re-uploads sphere data only when a step,
// reset or pour changed it; frames in between only change the interpolation fraction.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "app/camera.h"
#include "app/previous_positions.h"
#include "engine/character.h"
#include "engine/fixed_step_loop.h"
#include "engine/pour_scene.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"

namespace ballpit {

struct SessionOptions {
  // "play": the pit with the character (app/play_scene.h); "pour": shared/SCENES.md's pour;
  // or a scene file (.json, scenes/README.md), character and all.
  std::string scene = "play";
  std::vector<std::string> set = {};  // a scene file's field overrides ("a.b=v", engine/scene_file.h)
  std::size_t spheres = 0;  // 0: the scene's default (play 40,000; pour 10,000; a file's own)
  int threads = 0;          // 0: all hardware threads
  ColliderKind colliders = ColliderKind::Capsules;  // play only: a scene file names its own

  bool uses_scene_file() const { return scene.ends_with(".json"); }
};

// What the renderer needs from a frame of the simulation.
struct SphereRenderState {
  std::span<const Vec3> position;
  std::span<const float> radius;
  std::span<const std::uint32_t> color;
  std::span<const std::uint32_t> entity;          // entity index of each row
  std::span<const Vec3> previous_by_entity;       // empty when not interpolating
  float alpha = 1.0f;                             // 0: previous step, 1: latest step
  std::uint64_t version = 0;                      // changes whenever the columns change
};

class Session {
 public:
  explicit Session(const SessionOptions& options);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Rebuilds the scene from its options; the solver settings the UI changed are kept.
  void reset();
  // Advances by real time (unit: s) unless paused; returns the steps taken.
  int advance(double real_seconds);
  // One fixed step, paused or not.
  void single_step();
  // Drops `count` more balls into the pit from above the highest one.
  void pour(std::size_t count);

  bool paused = false;

  // Run-time settings; each validates and applies to every material and the pit.
  void set_restitution(float e);
  void set_friction(float mu);
  void set_substeps(int substeps);
  void set_solve_sweeps(int sweeps);
  void set_narrowphase(NarrowphaseMode mode);
  float restitution() const;
  float friction() const;

  World& world() { return *world_; }
  const World& world() const { return *world_; }
  Scheduler& scheduler() { return *scheduler_; }
  const Scheduler& scheduler() const { return *scheduler_; }
  int threads() const { return threads_; }
  const SessionOptions& options() const { return options_; }

  SphereRenderState sphere_render_state() const;
  // Interpolation fraction for everything drawn: 1 (the latest step as it is) while paused or
  // right after a single step, reset or pour; the fixed-step loop's fraction otherwise.
  float alpha() const;

  // The character, when the scene has one (the play scene does; pour does not).
  bool has_character() const { return world_->characters.size() > 0; }
  void set_character_input(const ControllerInput& input);
  // Root position between the last two steps (unit: m).
  Vec3 character_position() const;
  ColliderKind collider_kind() const { return options_.colliders; }
  // Refits the character's colliders as the other kind, keeping where it stands.
  void set_collider_kind(ColliderKind kind);
  // Height the settled balls would fill to if spread over the floor (unit: m): frames the
  // camera and scales the renderer's depth darkening.
  float fill_height() const { return fill_height_; }
  std::uint64_t steps_taken() const { return world_->step_count; }

 private:
  void build();
  void rebuild_scheduler();
  void update_fill_height();

  SessionOptions options_;
  int threads_ = 1;
  std::unique_ptr<World> world_;
  std::unique_ptr<Scheduler> scheduler_;
  std::unique_ptr<FixedStepLoop> loop_;
  PreviousPositions* previous_ = nullptr;  // owned by scheduler_
  std::shared_ptr<const Model> model_;     // the character's, imported once per session
  std::optional<SceneFile> scene_file_;    // read once: a reset rebuilds the same scene
  CharacterDesc character_desc_;           // how the character was spawned (a collider switch respawns it)
  std::uint64_t version_ = 0;
  std::uint64_t pours_ = 0;
  float fill_height_ = 0.0f;
  // After a single step, reset or pour, draw the latest state as it is until time advances
  // again: there is no "between" to interpolate.
  bool show_latest_ = true;
  // Settings the UI changed, re-applied after a reset.
  Material material_{0.5f, 0.5f};
  SolverSettings solver_;
  bool solver_overridden_ = false;
};

// The view the app opens with: the character from its front left when the scene has one,
// the whole pit otherwise.
OrbitCamera default_camera(const Session& session);

}  // namespace ballpit
