// Scene files: a scene's parameters as JSON (scenes/*.json), read strictly: every key must be
// known and every value of the expected type and range; errors name the file, the field path
// and what was expected. A scene is a pit, sphere populations (engine/populations.h), an
// optional character (which makes it a pit-character scene, shared/SCENES.md), the step, the
// gravity, the solver settings and the features it uses.
// Decisions:
// - `--set a.b=v` edits the scene's complete JSON (every field written out, defaults
//   included) before it is read again, so an override reaches any field, list elements too
//   (populations.0.radius=0.05), and is checked exactly like the file.
// - Only what a scene uses is built: features say whether balls spin (angular state, derived
//   from friction or a starting spin unless stated) and whether the character is used (derived
//   from the section).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "engine/character.h"
#include "engine/clip_sources.h"
#include "engine/math.h"
#include "engine/model_import.h"
#include "engine/populations.h"
#include "engine/settings.h"

namespace ballpit {

class World;

// The pit. Omitted sizes are the pour's: half width L/2 with L = sqrt(N * 5.6e-4) m for the
// scene's N spheres (all populations), 20 m walls, no lid.
struct ScenePit {
  float half_width = 0.0f;    // (unit: m); 0: automatic, as above
  float wall_height = 20.0f;  // (unit: m)
  bool closed = false;        // a lid at wall_height
  std::optional<Material> material;  // floor and walls; unset: the first population's (the pour's one material)
};

// The character section: the model, its clips and colliders, and how it moves. Built by the
// pit-character rules (systems/pit_character_scene.h).
struct SceneCharacter {
  std::string model = kDefaultModelPath;  // model file (assimp); in a file, relative to the file's folder
  float height = 1.8f;  // the bind pose is scaled to this height (unit: m), unless scale is set
  float scale = 0.0f;   // model units -> m; 0: from height
  // idle, walk, run, jump, kick (engine/clip_sources.h): a clip of `model` by name, or a source
  // (another file, a range of a take, root motion made in place); jump and kick may be none.
  RoleClips clips = {ClipSource::named(marine::kIdleClip), ClipSource::named(marine::kWalkClip),
                     ClipSource::named(marine::kRunClip), ClipSource::named(marine::kJumpClip),
                     ClipSource::named(marine::kKickClip)};
  Vec3 forward = Vec3::UnitZ();  // the model's facing axis in its own space
  ColliderKind colliders = ColliderKind::Capsules;
  bool scripted = true;  // "control": "script" follows `path`; "player": input from the app (idle headless)
  std::vector<ScriptSegment> path = default_path();
  int settle_steps = 300;          // steps the balls settle around the standing character first
  float foot_clearance_r = 2.2f;   // lowest collider this many (largest) ball radii above the floor
  ControllerSettings controller;

  // shared/SCENES.md's path: 3 s walk, 2 s walk turning left, 3 s run, 2 s idle.
  static std::vector<ScriptSegment> default_path();
};

// A feature a scene may state, or leave to be derived from the rest of the scene.
enum class FeatureSwitch : std::uint8_t { Auto, On, Off };

struct SceneFeatures {
  FeatureSwitch angular = FeatureSwitch::Auto;    // Auto: spin state when any population has friction or spin
  FeatureSwitch character = FeatureSwitch::Auto;  // Auto: when there is a character section; Off ignores it
  // Sleeping is the third feature; it lives in SolverSettings::sleeping ("features.sleeping" in
  // the file), off by default as the pour is measured.
};

struct SceneFile {
  float dt = 1.0f / 60.0f;   // fixed step (unit: s)
  int steps = 600;           // steps a headless run takes (after settling, with a character)
  std::uint32_t seed = 42;   // lattice jitter and radius distributions
  Vec3 gravity = Vec3(0.0f, -9.81f, 0.0f);  // (unit: m/s^2)
  ScenePit pit;
  std::vector<Population> populations = {Population{}};  // the pour's 10,000 balls
  std::optional<SceneCharacter> character;
  SceneFeatures features;
  SolverSettings solver = [] {
    SolverSettings s;
    s.sleeping = false;
    return s;
  }();
  // Not part of the file: names it in errors found while building (an unknown clip name).
  std::string source = "the default scene";

  std::size_t total_spheres() const;
  float pit_half_width() const;  // as given, or the automatic one (unit: m)
  bool uses_angular() const;
  bool uses_character() const;
};

// Every field, so the output is a complete scene file (the embedded default is this of
// SceneFile{}). A missing optional section (pit material, character) is left out.
nlohmann::ordered_json scene_to_json(const SceneFile& scene);

// Throws ballpit::Error "SOURCE: FIELD.PATH: expected ..." for an unknown key, a wrong type or
// a value out of range (a negative radius, a pit narrower than a sphere, a model file that
// does not exist). Missing keys keep their defaults.
SceneFile parse_scene(const nlohmann::ordered_json& j, const std::string& source);

// Applies "a.b.c=value" (value as JSON, or as a string if it is not JSON) to j: objects are
// entered or created, list elements named by index (the index one past the end appends).
// Setting one of two alternative keys (width/half_width, mass/density, height/scale) removes
// the other. Throws ballpit::Error naming the assignment if the path cannot be followed; an
// unknown key is refused by parse_scene, with its path.
void apply_override(nlohmann::ordered_json& j, const std::string& assignment);

// The scenes built into the binary, by name: "pour" (SceneFile{}) and "pit-character".
bool is_builtin_scene(const std::string& name);
SceneFile builtin_scene(const std::string& name);

// Reads the file (empty path or a built-in scene's name: that scene), applies the overrides to
// its complete JSON, parses.
SceneFile load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// The world settings a scene sets: pit, materials, gravity, step, solver, angular state.
void configure_scene(const SceneFile& scene, World& world);

// Builds a scene without a character into an empty world: configure_scene, then the
// populations. A scene that uses a character is built by setup_scene (systems/scene_setup.h),
// which has the character systems; this throws ballpit::Error for one.
void build_scene(const SceneFile& scene, World& world);

}  // namespace ballpit
