#include "engine/scene_file.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <limits>
#include <utility>

#include <nlohmann/json.hpp>

#include "engine/error.h"
#include "engine/json_fields.h"
#include "engine/pour_scene.h"
#include "engine/scene_file_sections.h"
#include "engine/world.h"

namespace ballpit {

namespace {

Json switch_json(FeatureSwitch s) {
  if (s == FeatureSwitch::Auto) return "auto";
  return s == FeatureSwitch::On;
}

void read_switch(const JsonFields& f, const std::string& key, FeatureSwitch& out) {
  const Json* v = f.find(key);
  if (!v) return;
  if (v->is_boolean()) out = v->get<bool>() ? FeatureSwitch::On : FeatureSwitch::Off;
  else if (v->is_string() && *v == "auto") out = FeatureSwitch::Auto;
  else f.fail(f.field(key), "expected \"auto\", true or false, got " + json_type_name(*v));
}

void parse_pit(const Json& j, ScenePit& pit, const std::string& source) {
  JsonFields f(j, "pit", source, {"half_width", "width", "wall_height", "closed", "material"});
  if (f.find("half_width") && f.find("width")) f.fail(f.field("width"), "expected either half_width or width, not both");
  for (const char* key : {"half_width", "width"}) {
    const Json* v = f.find(key);
    if (!v || (v->is_string() && *v == "auto")) continue;
    if (!v->is_number()) f.fail(f.field(key), "expected \"auto\" or a number > 0 (m), got " + json_type_name(*v));
    f.number(key, pit.half_width, 0.0f, kNoLimit, true, "m");
    if (std::string(key) == "width") pit.half_width *= 0.5f;
  }
  f.number("wall_height", pit.wall_height, 0.0f, kNoLimit, true, "m");
  f.boolean("closed", pit.closed);
  if (const Json* m = f.find("material"); m && !(m->is_string() && *m == "auto")) {
    JsonFields mf(*m, f.field("material"), source, {"restitution", "friction"});
    Material mat;
    mf.number("restitution", mat.restitution, 0.0f, 1.0f, false, "unitless");
    mf.number("friction", mat.friction, 0.0f, kNoLimit, false, "unitless");
    pit.material = mat;
  }
}

void parse_solver(const Json& j, SolverSettings& v, const std::string& source) {
  JsonFields f(j, "solver", source,
               {"substeps", "solve_sweeps", "push_out_rate", "push_out_speed", "restitution_threshold", "linear_damping",
                "angular_damping", "narrowphase", "sleep_speed", "sleep_time", "wake_speed"});
  f.integer("substeps", v.substeps, 1, 64);
  f.integer("solve_sweeps", v.solve_sweeps, 1, kMaxSolveSweeps);
  f.number("push_out_rate", v.push_out_rate, 0.0f, 1.0f, true, "unitless");
  f.number("push_out_speed", v.push_out_speed, 0.0f, kNoLimit, true, "m/s");
  f.number("restitution_threshold", v.restitution_threshold, 0.0f, kNoLimit, false, "m/s");
  f.number("linear_damping", v.linear_damping, 0.0f, kNoLimit, false, "1/s");
  f.number("angular_damping", v.angular_damping, 0.0f, kNoLimit, false, "1/s");
  int mode = v.narrowphase == NarrowphaseMode::Naive ? 1 : 0;
  f.choice("narrowphase", mode, {"grid", "naive"});
  v.narrowphase = mode == 1 ? NarrowphaseMode::Naive : NarrowphaseMode::Grid;
  f.number("sleep_speed", v.sleep_speed, 0.0f, kNoLimit, false, "m/s");
  f.number("sleep_time", v.sleep_time, 0.0f, kNoLimit, true, "s");
  f.number("wake_speed", v.wake_speed, 0.0f, kNoLimit, false, "m/s");
}

// Checks that need the whole scene: a stated character needs its section, every sphere fits
// between the walls, a spinning population has the angular state, every box lies inside the pit.
void check_scene(const SceneFile& s, const Json& j) {
  if (s.features.character == FeatureSwitch::On && !s.character)
    scene_error(s.source, "features.character", "expected \"auto\" or false: the scene has no character section");
  const float half = s.pit_half_width();
  const bool automatic = s.pit.half_width <= 0.0f;
  const bool by_width = j.contains("pit") && j.at("pit").is_object() && j.at("pit").contains("width");
  for (std::size_t k = 0; k < s.populations.size(); ++k) {
    const Population& p = s.populations[k];
    const std::string at = "populations." + std::to_string(k);
    const float r = p.radius.largest();
    if (!(half > r)) {
      if (automatic)
        scene_error(s.source, at + ".radius",
                    "a sphere of radius " + number_text(r) + " m does not fit in the pit of " +
                        std::to_string(s.total_spheres()) + " spheres (half width " + number_text(half) +
                        " m); expected a smaller radius");
      scene_error(s.source, by_width ? "pit.width" : "pit.half_width",
                  "expected a pit wider than one sphere (" + at + " has radius " + number_text(r) + " m), got " +
                      (by_width ? "width " + number_text(2.0f * half) : "half width " + number_text(half)) + " m");
    }
    if (p.spin != Vec3::Zero() && s.features.angular == FeatureSwitch::Off)
      scene_error(s.source, at + ".spin",
                  "expected [0, 0, 0] with features.angular false (spin needs the angular state), got [" +
                      number_text(p.spin.x()) + ", " + number_text(p.spin.y()) + ", " + number_text(p.spin.z()) +
                      "]; set features.angular to \"auto\" or true");
    if (p.placement.kind == Placement::Kind::Box) {
      const Vec3& lo = p.placement.min;
      const Vec3& hi = p.placement.max;
      const bool inside = lo.x() >= -half && lo.z() >= -half && hi.x() <= half && hi.z() <= half && lo.y() >= 0.0f &&
                          hi.y() <= s.pit.wall_height;
      if (!inside)
        scene_error(s.source, at + ".placement",
                    "expected a box inside the pit (x and z within +-" + number_text(half) + " m, y from 0 to " +
                        number_text(s.pit.wall_height) + " m)");
    }
  }
}

// Keys of which a scene gives one or the other: setting one by --set drops its twin.
constexpr std::pair<const char*, const char*> kAlternatives[] = {
    {"half_width", "width"}, {"mass", "density"}, {"height", "scale"}};

bool is_index(const std::string& key) {
  return !key.empty() && key.size() < 10 && std::all_of(key.begin(), key.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

}  // namespace

std::vector<ScriptSegment> SceneCharacter::default_path() {
  const ControllerInput walk{1.0f, 0.0f, false};
  const ControllerInput walk_left{1.0f, 1.0f, false};
  const ControllerInput run{1.0f, 0.0f, true};
  const ControllerInput idle{};
  return {{3.0f, walk}, {2.0f, walk_left}, {3.0f, run}, {2.0f, idle}};
}

std::size_t SceneFile::total_spheres() const {
  std::size_t n = 0;
  for (const Population& p : populations) n += p.count;
  return n;
}

float SceneFile::pit_half_width() const {
  if (pit.half_width > 0.0f) return pit.half_width;
  // The pour's formula, evaluated exactly as PourScene does so the default scene is the pour.
  PourScene pour;
  pour.spheres = total_spheres();
  return 0.5f * pour.pit_width();
}

bool SceneFile::uses_angular() const {
  if (features.angular != FeatureSwitch::Auto) return features.angular == FeatureSwitch::On;
  // Friction is what spins a sphere (pairs combine by geometric mean, so a frictionless ball
  // gets no torque even from a rough wall).
  // A population that starts spinning needs the state to hold its spin.
  return std::any_of(populations.begin(), populations.end(), [](const Population& p) {
    return p.material.friction > 0.0f || p.spin != Vec3::Zero();
  });
}

bool SceneFile::uses_character() const { return character.has_value() && features.character != FeatureSwitch::Off; }

Json scene_to_json(const SceneFile& s) {
  Json j;
  j["dt"] = s.dt;
  j["steps"] = s.steps;
  j["seed"] = s.seed;
  j["gravity"] = {s.gravity.x(), s.gravity.y(), s.gravity.z()};
  Json pit;
  pit["half_width"] = s.pit.half_width > 0.0f ? Json(s.pit.half_width) : Json("auto");
  pit["wall_height"] = s.pit.wall_height;
  pit["closed"] = s.pit.closed;
  pit["material"] = s.pit.material ? Json{{"restitution", s.pit.material->restitution}, {"friction", s.pit.material->friction}}
                                   : Json("auto");
  j["pit"] = pit;
  Json populations = Json::array();
  for (const Population& p : s.populations) populations.push_back(population_to_json(p));
  j["populations"] = populations;
  if (s.character) j["character"] = character_to_json(*s.character);
  j["features"] = {{"angular", switch_json(s.features.angular)},
                   {"character", switch_json(s.features.character)},
                   {"sleeping", s.solver.sleeping}};
  const SolverSettings& v = s.solver;
  j["solver"] = {{"substeps", v.substeps},
                 {"solve_sweeps", v.solve_sweeps},
                 {"push_out_rate", v.push_out_rate},
                 {"push_out_speed", v.push_out_speed},
                 {"restitution_threshold", v.restitution_threshold},
                 {"linear_damping", v.linear_damping},
                 {"angular_damping", v.angular_damping},
                 {"narrowphase", v.narrowphase == NarrowphaseMode::Naive ? "naive" : "grid"},
                 {"sleep_speed", v.sleep_speed},
                 {"sleep_time", v.sleep_time},
                 {"wake_speed", v.wake_speed}};
  return j;
}

SceneFile parse_scene(const Json& j, const std::string& source) {
  SceneFile s;
  s.source = source;
  if (j.is_object() && j.contains("pour"))
    scene_error(source, "pour", "unknown key: the pour section of older scene files is now \"pit\" and \"populations\" "
                                "(see scenes/pour.json)");
  JsonFields top(j, "", source,
                 {"dt", "steps", "seed", "gravity", "pit", "populations", "character", "features", "solver"});
  top.number("dt", s.dt, 0.0f, kNoLimit, true, "s");
  top.integer("steps", s.steps, 1, std::numeric_limits<int>::max());
  top.integer("seed", s.seed, 0, 0xffffffffLL);
  top.vec3("gravity", s.gravity, "m/s^2");
  if (const Json* pit = top.find("pit")) parse_pit(*pit, s.pit, source);
  if (const Json* list = top.find("populations")) {
    if (!list->is_array() || list->empty())
      top.fail("populations", "expected a list of at least one population, got " + json_type_name(*list));
    s.populations.clear();
    for (std::size_t k = 0; k < list->size(); ++k)
      s.populations.push_back(parse_population((*list)[k], "populations." + std::to_string(k), source));
  }
  if (const Json* c = top.find("character"); c && !c->is_null()) s.character = parse_character(*c, source);
  if (const Json* features = top.find("features")) {
    JsonFields f(*features, "features", source, {"angular", "character", "sleeping"});
    read_switch(f, "angular", s.features.angular);
    read_switch(f, "character", s.features.character);
    f.boolean("sleeping", s.solver.sleeping);
  }
  if (const Json* solver = top.find("solver")) parse_solver(*solver, s.solver, source);
  check_scene(s, j);
  return s;
}

void apply_override(Json& j, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--set '" + assignment + "': expected key=value, e.g. populations.0.count=5000");
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  auto fail = [&](const std::string& at, const std::string& what) {
    throw Error("--set '" + assignment + "': '" + at + "' " + what);
  };
  Json* target = &j;
  std::string parent;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    const std::string key = path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    const std::string here = path.substr(0, dot);
    if (key.empty()) fail(here, "has an empty key; expected a.b.c");
    if (target->is_array()) {
      // A list element by index; the index one past the end appends one.
      if (!is_index(key)) fail(here, "names no element of the list '" + parent + "'; expected an index 0.." + std::to_string(target->size()));
      const std::size_t index = std::stoul(key);
      if (index > target->size())
        fail(here, "is past the end of the list '" + parent + "' (" + std::to_string(target->size()) +
                       " elements); expected an index 0.." + std::to_string(target->size()));
      if (index == target->size()) target->push_back(Json::object());
      target = &(*target)[index];
    } else {
      if (!target->is_object()) *target = Json::object();  // "auto", a number radius: replaced by an object
      for (const auto& [a, b] : kAlternatives) {
        if (key == a) target->erase(b);
        if (key == b) target->erase(a);
      }
      Json& next = (*target)[key];
      // A missing list is made when the next key is an index: populations.0.count on {}.
      if (next.is_null() && dot != std::string::npos) {
        const std::size_t after = path.find('.', dot + 1);
        if (is_index(path.substr(dot + 1, after == std::string::npos ? std::string::npos : after - dot - 1))) next = Json::array();
      }
      target = &next;
    }
    if (dot == std::string::npos) break;
    parent = here;
    begin = dot + 1;
  }
  Json value = Json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;  // a bare word is a string: narrowphase=naive
  *target = std::move(value);
}

bool is_builtin_scene(const std::string& name) { return name == "pour" || name == "pit-character"; }

SceneFile builtin_scene(const std::string& name) {
  SceneFile s;
  if (name == "pit-character") {
    s.character = SceneCharacter{};
    s.source = "the built-in pit-character scene";
  } else if (name != "pour") {
    throw Error("unknown built-in scene '" + name + "' (known: pour, pit-character)");
  }
  return s;
}

namespace {

// A relative model (or clip file) path in a scene file names a file beside the scene, wherever
// it is run from (a path given by --set stays relative to the working directory, as on a
// command line).
void resolve_model_path(Json& j, const std::string& scene_path) {
  if (!j.is_object()) return;
  auto character = j.find("character");
  if (character == j.end() || !character->is_object()) return;
  auto resolve = [&](Json& file) {
    if (!file.is_string()) return;  // parse_scene names the error
    const std::filesystem::path given = file.get<std::string>();
    if (given.empty() || given.is_absolute() || is_builtin_model(given.string())) return;
    file = (std::filesystem::path(scene_path).parent_path() / given).lexically_normal().string();
  };
  if (auto model = character->find("model"); model != character->end()) resolve(*model);
  // So are the clip files of character.clips (engine/clip_sources.h).
  auto clips = character->find("clips");
  if (clips == character->end() || !clips->is_object()) return;
  for (Json& source : *clips)
    if (source.is_object())
      if (auto file = source.find("file"); file != source.end()) resolve(*file);
}

}  // namespace

SceneFile load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  Json j;
  std::string source;
  if (path.empty() || is_builtin_scene(path)) {
    const SceneFile builtin = builtin_scene(path.empty() ? "pour" : path);
    j = scene_to_json(builtin);
    source = builtin.source;
  } else {
    source = path;
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open the scene file");
    try {
      j = Json::parse(in);
    } catch (const Json::exception& e) {
      // parse_error, and out_of_range for a number beyond double (1e400): both are the file's.
      throw Error(path + ": not valid JSON (" + e.what() + ")");
    }
    resolve_model_path(j, path);
  }
  if (overrides.empty()) return parse_scene(j, source);
  // Overrides edit the complete scene, so every field is there to be set, defaults included.
  j = scene_to_json(parse_scene(j, source));
  for (const std::string& o : overrides) apply_override(j, o);
  return parse_scene(j, source + " with --set overrides");
}

void configure_scene(const SceneFile& scene, World& world) {
  const Material first = scene.populations.empty() ? Material{} : scene.populations.front().material;
  world.pit.half_width = scene.pit_half_width();
  world.pit.wall_height = scene.pit.wall_height;
  world.pit.closed = scene.pit.closed;
  world.pit.material = scene.pit.material.value_or(first);
  world.materials.assign(1, first);
  world.set_gravity(scene.gravity);
  world.set_step(scene.dt);
  world.solver = scene.solver;
  world.enable_angular(scene.uses_angular());
  world.validate_settings();
}

void build_scene(const SceneFile& scene, World& world) {
  if (scene.uses_character())
    throw Error(scene.source + ": character: this scene has a character; build it with setup_scene "
                "(systems/scene_setup.h), which has the character systems");
  configure_scene(scene, world);
  add_populations(world, scene.populations, scene.seed, scene.source);
}

}  // namespace ballpit
