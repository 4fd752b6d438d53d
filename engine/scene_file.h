// Scene files: a scene's parameters as JSON (scenes/*.json), read strictly: every key must be
// known and every value of the expected type and range; errors name the file, the field path
// and what was expected. Decision: `--set a.b=v` edits the JSON before it is read, so an
// override is checked exactly like the file, and a mistyped key is an error, never ignored.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "engine/math.h"
#include "engine/pour_scene.h"
#include "engine/settings.h"

namespace ballpit {

class World;

struct SceneFile {
  std::string kind = "pour";  // the only kind so far: the pour of shared/SCENES.md
  PourScene pour;
  // Applied after the scene is built. Defaults are the pour's: sleeping off, as measured.
  SolverSettings solver = [] {
    SolverSettings s;
    s.sleeping = false;
    return s;
  }();
  Vec3 gravity = Vec3(0.0f, -9.81f, 0.0f);  // (unit: m/s^2)
};

// Every field, so the output is a complete scene file (the embedded default is this of
// SceneFile{}).
nlohmann::ordered_json scene_to_json(const SceneFile& scene);

// Throws ballpit::Error "SOURCE: FIELD.PATH: expected ..." for an unknown key, a wrong type or
// a value out of range. Missing keys keep their defaults.
SceneFile parse_scene(const nlohmann::ordered_json& j, const std::string& source);

// Applies "a.b.c=value" (value as JSON, or as a string if it is not JSON) to j. Throws
// ballpit::Error naming the assignment if the path is not a field of a scene file.
void apply_override(nlohmann::ordered_json& j, const std::string& assignment);

// Reads the file (empty path: the embedded default scene), applies the overrides, parses.
SceneFile load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// Builds the scene into an empty world and applies its solver settings and gravity.
void build_scene(const SceneFile& scene, World& world);

}  // namespace ballpit
