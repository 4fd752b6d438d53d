#include "engine/scene_file_sections.h"

#include <cmath>
#include <filesystem>

#include "engine/marine/marine.h"

namespace ballpit {

namespace {

// The kind a variant object names under `key` ("distribution", "scheme", "kind"), so the keys
// it may hold are known before JsonFields checks them. Absent: `fallback`.
int variant(const Json& j, const std::string& key, const std::string& path, const std::string& source,
            std::initializer_list<const char*> kinds, int fallback) {
  if (!j.is_object()) scene_error(source, path, "expected an object, got " + json_type_name(j));
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  Json one = Json::object();
  one[key] = *it;
  int kind = fallback;
  JsonFields(one, path, source, {key}).choice(key, kind, kinds);
  return kind;
}

// A number the section cannot do without (a distribution's bounds): missing is an error.
float required_number(const JsonFields& f, const std::string& key, float lo, bool lo_open, const char* unit) {
  const Json* v = f.find(key);
  if (!v) f.fail(f.field(key), std::string("missing: expected a number ") + (lo_open ? "> " : ">= ") + number_text(lo) + " (" + unit + ")");
  return f.number_value(f.field(key), *v, lo, kNoLimit, lo_open, unit);
}

Json radius_to_json(const RadiusSpec& r) {
  switch (r.kind) {
    case RadiusSpec::Kind::Uniform:
      return {{"distribution", "uniform"}, {"min", r.min}, {"max", r.max}};
    case RadiusSpec::Kind::Normal:
      return {{"distribution", "normal"}, {"mean", r.mean}, {"sd", r.sd}, {"min", r.min}, {"max", r.max}};
    case RadiusSpec::Kind::Fixed:
      break;
  }
  return r.value;
}

RadiusSpec parse_radius(const Json& j, const std::string& path, const std::string& source) {
  RadiusSpec r;
  if (!j.is_object()) {
    if (!j.is_number())
      scene_error(source, path,
                  "expected a number (m) or a distribution {\"distribution\": \"uniform\" or \"normal\", ...}, got " +
                      json_type_name(j));
    r.value = JsonFields(Json::object(), "", source, {}).number_value(path, j, 0.0f, kNoLimit, true, "m");
    return r;
  }
  const int kind = variant(j, "distribution", path, source, {"uniform", "normal"}, -1);
  if (kind < 0) scene_error(source, path + ".distribution", "missing: expected \"uniform\" or \"normal\"");
  if (kind == 0) {
    JsonFields f(j, path, source, {"distribution", "min", "max"});
    r.kind = RadiusSpec::Kind::Uniform;
    r.min = required_number(f, "min", 0.0f, true, "m");
    r.max = required_number(f, "max", r.min, false, "m");
  } else {
    // Normal, clamped to [min, max] so no radius is <= 0 or wider than the lattice allows.
    JsonFields f(j, path, source, {"distribution", "mean", "sd", "min", "max"});
    r.kind = RadiusSpec::Kind::Normal;
    r.mean = required_number(f, "mean", 0.0f, true, "m");
    r.sd = required_number(f, "sd", 0.0f, false, "m");
    r.min = required_number(f, "min", 0.0f, true, "m");
    r.max = required_number(f, "max", r.min, false, "m");
  }
  return r;
}

constexpr std::initializer_list<const char*> kSchemes = {"palette", "solid", "by_radius", "by_height"};

Json color_to_json(const ColorScheme& c) {
  Json j;
  j["scheme"] = kSchemes.begin()[static_cast<int>(c.kind)];
  switch (c.kind) {
    case ColorScheme::Kind::Palette: {
      Json list = Json::array();
      for (std::uint32_t rgba : c.palette) list.push_back(color_text(rgba));
      j["palette"] = list;
      break;
    }
    case ColorScheme::Kind::Solid:
      j["color"] = color_text(c.color);
      break;
    case ColorScheme::Kind::ByRadius:
    case ColorScheme::Kind::ByHeight:
      j["from"] = color_text(c.from);
      j["to"] = color_text(c.to);
      break;
  }
  return j;
}

ColorScheme parse_color(const Json& j, const std::string& path, const std::string& source) {
  ColorScheme c;
  c.kind = static_cast<ColorScheme::Kind>(variant(j, "scheme", path, source, kSchemes, 0));
  switch (c.kind) {
    case ColorScheme::Kind::Palette: {
      JsonFields f(j, path, source, {"scheme", "palette"});
      if (const Json* list = f.find("palette")) {
        if (!list->is_array() || list->empty())
          f.fail(f.field("palette"), "expected a list of colours [\"#rrggbb\", ...], got " + json_type_name(*list));
        c.palette.clear();
        for (std::size_t i = 0; i < list->size(); ++i) {
          Json one = {{std::to_string(i), (*list)[i]}};
          std::uint32_t rgba = 0;
          JsonFields(one, f.field("palette"), source, {std::to_string(i)}).color(std::to_string(i), rgba);
          c.palette.push_back(rgba);
        }
      }
      break;
    }
    case ColorScheme::Kind::Solid: {
      JsonFields f(j, path, source, {"scheme", "color"});
      f.color("color", c.color);
      break;
    }
    case ColorScheme::Kind::ByRadius:
    case ColorScheme::Kind::ByHeight: {
      JsonFields f(j, path, source, {"scheme", "from", "to"});
      f.color("from", c.from);
      f.color("to", c.to);
      break;
    }
  }
  return c;
}

Json placement_to_json(const Placement& p) {
  Json j;
  j["kind"] = p.kind == Placement::Kind::Box ? "box" : "lattice";
  j["spacing_r"] = p.spacing_r;
  j["jitter_r"] = p.jitter_r;
  if (p.kind == Placement::Kind::Box) {
    j["min"] = {p.min.x(), p.min.y(), p.min.z()};
    j["max"] = {p.max.x(), p.max.y(), p.max.z()};
  }
  return j;
}

Placement parse_placement(const Json& j, const std::string& path, const std::string& source) {
  Placement p;
  p.kind = static_cast<Placement::Kind>(variant(j, "kind", path, source, {"lattice", "box"}, 0));
  const bool box = p.kind == Placement::Kind::Box;
  JsonFields f(j, path, source,
               box ? std::vector<std::string>{"kind", "spacing_r", "jitter_r", "min", "max"}
                   : std::vector<std::string>{"kind", "spacing_r", "jitter_r"});
  f.number("jitter_r", p.jitter_r, 0.0f, 1.0f, false, "largest radii");
  f.number("spacing_r", p.spacing_r, 0.0f, kNoLimit, true, "largest radii");
  // Neighbours are spacing apart and each moves up to jitter: they must not start overlapping.
  if (!(p.spacing_r >= 2.0f + 2.0f * p.jitter_r))
    f.fail(f.field("spacing_r"), "expected a number >= 2 + 2 x jitter_r = " + number_text(2.0f + 2.0f * p.jitter_r) +
                                     " (largest radii), so no two spheres start overlapping, got " +
                                     number_text(p.spacing_r));
  if (box) {
    if (!f.find("min") || !f.find("max")) f.fail(f.field(f.find("min") ? "max" : "min"), "missing: expected [x, y, z] (m)");
    f.vec3("min", p.min, "m");
    f.vec3("max", p.max, "m");
    if (!(p.min.array() < p.max.array()).all())
      f.fail(f.field("max"), "expected a corner above min on every axis, got a box from " + f.find("min")->dump() +
                                 " to " + f.find("max")->dump());
  }
  return p;
}

}  // namespace

Json population_to_json(const Population& p) {
  Json j;
  j["count"] = p.count;
  j["radius"] = radius_to_json(p.radius);
  if (p.density > 0.0f) j["density"] = p.density;
  else j["mass"] = p.mass;
  j["material"] = {{"restitution", p.material.restitution}, {"friction", p.material.friction}};
  j["color"] = color_to_json(p.color);
  j["placement"] = placement_to_json(p.placement);
  j["velocity"] = {p.velocity.x(), p.velocity.y(), p.velocity.z()};
  j["velocity_jitter"] = p.velocity_jitter;
  j["spin"] = {p.spin.x(), p.spin.y(), p.spin.z()};
  return j;
}

Population parse_population(const Json& j, const std::string& path, const std::string& source) {
  Population p;
  JsonFields f(j, path, source,
               {"count", "radius", "mass", "density", "material", "color", "placement", "velocity", "velocity_jitter",
                "spin"});
  f.integer("count", p.count, 1, 1LL << 32);
  if (const Json* r = f.find("radius")) p.radius = parse_radius(*r, f.field("radius"), source);
  if (f.find("mass") && f.find("density"))
    f.fail(f.field("density"), "expected either mass or density, not both");
  f.number("mass", p.mass, 0.0f, kNoLimit, true, "kg");
  // The solver works with 1/m: a mass below 1/FLT_MAX (2.9e-39 kg) makes it infinite.
  if (!std::isfinite(1.0f / p.mass))
    f.fail(f.field("mass"), "expected a mass whose inverse is finite (> 2.9e-39 kg), got " + number_text(p.mass));
  f.number("density", p.density, 0.0f, kNoLimit, true, "kg/m^3");
  if (const Json* m = f.find("material")) {
    JsonFields mf(*m, f.field("material"), source, {"restitution", "friction"});
    mf.number("restitution", p.material.restitution, 0.0f, 1.0f, false, "unitless");
    mf.number("friction", p.material.friction, 0.0f, kNoLimit, false, "unitless");
  }
  if (const Json* c = f.find("color")) p.color = parse_color(*c, f.field("color"), source);
  if (const Json* pl = f.find("placement")) p.placement = parse_placement(*pl, f.field("placement"), source);
  // Any finite velocity and spin: what the engine makes of a fast one is the solver's to bound.
  f.vec3("velocity", p.velocity, "m/s");
  f.number("velocity_jitter", p.velocity_jitter, 0.0f, kNoLimit, false, "m/s per axis");
  f.vec3("spin", p.spin, "rad/s");
  return p;
}

Json character_to_json(const SceneCharacter& c) {
  Json j;
  j["model"] = c.model;
  if (c.scale > 0.0f) j["scale"] = c.scale;
  else j["height"] = c.height;
  Json clips = Json::object();
  for (int role = 0; role < kClipRoles; ++role)
    clips[kClipRoleNames[static_cast<std::size_t>(role)]] = clip_source_to_json(c.clips[static_cast<std::size_t>(role)]);
  j["clips"] = clips;
  j["forward"] = {c.forward.x(), c.forward.y(), c.forward.z()};
  j["colliders"] = c.colliders == ColliderKind::Spheres ? "spheres" : "capsules";
  j["control"] = c.scripted ? "script" : "player";
  Json path = Json::array();
  for (const ScriptSegment& s : c.path)
    path.push_back({{"duration", s.duration}, {"forward", s.input.forward}, {"turn", s.input.turn}, {"run", s.input.run}});
  j["path"] = path;
  j["settle_steps"] = c.settle_steps;
  j["foot_clearance_r"] = c.foot_clearance_r;
  const ControllerSettings& k = c.controller;
  j["controller"] = {{"walk_speed", k.walk_speed},     {"run_speed", k.run_speed},   {"back_speed", k.back_speed},
                     {"turn_rate", k.turn_rate},       {"acceleration", k.acceleration},
                     {"blend_time", k.blend_time},     {"wall_clearance", k.wall_clearance}};
  return j;
}

SceneCharacter parse_character(const Json& j, const std::string& source) {
  SceneCharacter c;
  JsonFields f(j, "character", source,
               {"model", "height", "scale", "clips", "forward", "colliders", "control", "path", "settle_steps",
                "foot_clearance_r", "controller"});
  f.text("model", c.model);
  std::error_code ec;
  if (!is_builtin_model(c.model) && !std::filesystem::is_regular_file(c.model, ec))
    f.fail(f.field("model"), "expected an existing model file or \"" + std::string(marine::kModelName) + "\", '" +
                                 c.model + "' does not exist");
  if (f.find("height") && f.find("scale")) f.fail(f.field("scale"), "expected either height or scale, not both");
  f.number("height", c.height, 0.0f, kNoLimit, true, "m");
  f.number("scale", c.scale, 0.0f, kNoLimit, true, "m per model unit");
  if (const Json* clips = f.find("clips")) {
    JsonFields cf(*clips, f.field("clips"), source, {kClipRoleNames.begin(), kClipRoleNames.end()});
    // A role left out keeps the default model's clip, but an action left out is none: a model
    // of the user's has no clip of the default's names, and its actions are optional.
    for (int role = 0; role < kClipRoles; ++role) {
      ClipSource& out = c.clips[static_cast<std::size_t>(role)];
      if (const Json* v = cf.find(kClipRoleNames[static_cast<std::size_t>(role)]))
        out = parse_clip_source(*v, role, cf.field(kClipRoleNames[static_cast<std::size_t>(role)]), source);
      else if (role >= kFirstActionRole)
        out = ClipSource{};
    }
  }
  f.vec3("forward", c.forward, "model axis");
  if (!(std::hypot(c.forward.x(), c.forward.z()) > 0.0f))
    f.fail(f.field("forward"), "expected an axis with a horizontal (x, z) part, got " + f.find("forward")->dump());
  int colliders = c.colliders == ColliderKind::Spheres ? 1 : 0;
  f.choice("colliders", colliders, {"capsules", "spheres"});
  c.colliders = colliders == 1 ? ColliderKind::Spheres : ColliderKind::Capsules;
  int control = c.scripted ? 0 : 1;
  f.choice("control", control, {"script", "player"});
  c.scripted = control == 0;
  if (const Json* path = f.find("path")) {
    if (!path->is_array()) f.fail(f.field("path"), "expected a list of {duration, forward, turn, run}, got " + json_type_name(*path));
    c.path.clear();
    for (std::size_t i = 0; i < path->size(); ++i) {
      JsonFields sf((*path)[i], f.field("path." + std::to_string(i)), source, {"duration", "forward", "turn", "run"});
      ScriptSegment s;
      s.duration = required_number(sf, "duration", 0.0f, true, "s");
      sf.number("forward", s.input.forward, -1.0f, 1.0f, false, "-1 back .. 1 forward");
      sf.number("turn", s.input.turn, -1.0f, 1.0f, false, "-1 right .. 1 left");
      sf.boolean("run", s.input.run);
      c.path.push_back(s);
    }
  }
  f.integer("settle_steps", c.settle_steps, 0, 1 << 30);
  f.number("foot_clearance_r", c.foot_clearance_r, 0.0f, kNoLimit, false, "ball radii");
  if (const Json* k = f.find("controller")) {
    JsonFields kf(*k, f.field("controller"), source,
                  {"walk_speed", "run_speed", "back_speed", "turn_rate", "acceleration", "blend_time", "wall_clearance"});
    ControllerSettings& s = c.controller;
    kf.number("walk_speed", s.walk_speed, 0.0f, kNoLimit, false, "m/s, 0: the walk clip's");
    kf.number("run_speed", s.run_speed, 0.0f, kNoLimit, false, "m/s, 0: the run clip's");
    kf.number("back_speed", s.back_speed, 0.0f, kNoLimit, false, "m/s, 0: the walk speed");
    kf.number("turn_rate", s.turn_rate, 0.0f, kNoLimit, false, "rad/s");
    kf.number("acceleration", s.acceleration, 0.0f, kNoLimit, true, "m/s^2");
    kf.number("blend_time", s.blend_time, 0.0f, kNoLimit, true, "s");
    kf.number("wall_clearance", s.wall_clearance, 0.0f, kNoLimit, false, "m");
  }
  return c;
}

}  // namespace ballpit
