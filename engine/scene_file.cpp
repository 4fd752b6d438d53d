#include "engine/scene_file.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "engine/error.h"
#include "engine/world.h"

namespace ballpit {

namespace {

using Json = nlohmann::ordered_json;

std::string type_name(const Json& v) {
  if (v.is_number_integer()) return "integer " + v.dump();
  if (v.is_number()) return "number " + v.dump();
  if (v.is_string()) return "string " + v.dump();
  return std::string(v.type_name()) + (v.is_null() ? "" : " " + v.dump());
}

// One JSON object at a field path: unknown keys are refused up front, known ones read on demand.
class Fields {
 public:
  Fields(const Json& object, std::string path, const std::string& source, std::vector<std::string> known)
      : object_(object), path_(std::move(path)), source_(source) {
    if (!object.is_object()) fail(path_, "expected an object, got " + type_name(object));
    for (const auto& [key, value] : object.items()) {
      bool ok = false;
      for (const std::string& k : known) ok = ok || k == key;
      if (!ok) {
        std::string list;
        for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
        fail(field(key), "unknown key (known keys here: " + list + ")");
      }
    }
  }

  [[noreturn]] void fail(const std::string& field_path, const std::string& what) const {
    throw Error(source_ + ": " + (field_path.empty() ? std::string("(top level)") : field_path) + ": " + what);
  }
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Json* find(const std::string& key) const {
    auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }

  // A finite number in [lo, hi] (open at lo when lo_open).
  void number(const std::string& key, float& out, float lo, float hi, bool lo_open, const char* unit) const {
    const Json* v = find(key);
    if (!v) return;
    if (!v->is_number()) fail(field(key), std::string("expected a number (") + unit + "), got " + type_name(*v));
    const double x = v->get<double>();
    const bool ok = std::isfinite(x) && (lo_open ? x > lo : x >= lo) && x <= hi;
    if (!ok) {
      std::ostringstream range;
      range << (lo_open ? "> " : ">= ") << lo;
      if (hi < std::numeric_limits<float>::max()) range << " and <= " << hi;
      fail(field(key), "expected a number " + range.str() + " (" + unit + "), got " + v->dump());
    }
    out = static_cast<float>(x);
  }
  template <class Int>
  void integer(const std::string& key, Int& out, long long lo, long long hi) const {
    const Json* v = find(key);
    if (!v) return;
    if (!v->is_number_integer()) fail(field(key), "expected an integer, got " + type_name(*v));
    const long long x = v->get<long long>();
    if (x < lo || x > hi || (v->is_number_unsigned() && v->get<unsigned long long>() > static_cast<unsigned long long>(hi)))
      fail(field(key), "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + v->dump());
    out = static_cast<Int>(x);
  }
  void boolean(const std::string& key, bool& out) const {
    const Json* v = find(key);
    if (!v) return;
    if (!v->is_boolean()) fail(field(key), "expected true or false, got " + type_name(*v));
    out = v->get<bool>();
  }
  void vec3(const std::string& key, Vec3& out, const char* unit) const {
    const Json* v = find(key);
    if (!v) return;
    if (!v->is_array() || v->size() != 3) fail(field(key), std::string("expected [x, y, z] (") + unit + "), got " + type_name(*v));
    for (int a = 0; a < 3; ++a) {
      const Json& c = (*v)[static_cast<std::size_t>(a)];
      if (!c.is_number() || !std::isfinite(c.get<double>()))
        fail(field(key) + "[" + std::to_string(a) + "]", "expected a finite number, got " + type_name(c));
      out[a] = c.get<float>();
    }
  }

 private:
  const Json& object_;
  std::string path_;
  const std::string& source_;
};

constexpr float kMax = std::numeric_limits<float>::max();

std::string number_text(float x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace

Json scene_to_json(const SceneFile& s) {
  Json j;
  j["kind"] = s.kind;
  const PourScene& p = s.pour;
  j["pour"] = {{"spheres", p.spheres},         {"radius", p.radius}, {"mass", p.mass},
               {"restitution", p.restitution}, {"friction", p.friction}, {"wall_height", p.wall_height},
               {"seed", p.seed},               {"dt", p.dt},         {"steps", p.steps}};
  const SolverSettings& v = s.solver;
  j["solver"] = {{"substeps", v.substeps},
                 {"push_out_rate", v.push_out_rate},
                 {"push_out_speed", v.push_out_speed},
                 {"restitution_threshold", v.restitution_threshold},
                 {"linear_damping", v.linear_damping},
                 {"angular_damping", v.angular_damping},
                 {"narrowphase", v.narrowphase == NarrowphaseMode::Naive ? "naive" : "grid"},
                 {"sleeping", v.sleeping},
                 {"sleep_speed", v.sleep_speed},
                 {"sleep_time", v.sleep_time},
                 {"wake_speed", v.wake_speed}};
  j["gravity"] = {s.gravity.x(), s.gravity.y(), s.gravity.z()};
  return j;
}

SceneFile parse_scene(const Json& j, const std::string& source) {
  SceneFile s;
  Fields top(j, "", source, {"kind", "pour", "solver", "gravity"});
  if (const Json* kind = top.find("kind")) {
    if (!kind->is_string() || kind->get<std::string>() != "pour")
      top.fail("kind", "expected \"pour\" (the only scene kind so far), got " + type_name(*kind));
  }
  if (const Json* pour = top.find("pour")) {
    Fields f(*pour, "pour", source,
             {"spheres", "radius", "mass", "restitution", "friction", "wall_height", "seed", "dt", "steps"});
    PourScene& p = s.pour;
    f.integer("spheres", p.spheres, 1, 1LL << 32);
    f.number("radius", p.radius, 0.0f, kMax, true, "m");
    f.number("mass", p.mass, 0.0f, kMax, true, "kg");
    // The solver works with 1/m: a mass below 1/FLT_MAX (2.9e-39 kg) makes it infinite.
    if (!std::isfinite(1.0f / p.mass))
      f.fail("pour.mass", "expected a mass whose inverse is finite (> 2.9e-39 kg), got " + number_text(p.mass));
    f.number("restitution", p.restitution, 0.0f, 1.0f, false, "unitless");
    f.number("friction", p.friction, 0.0f, kMax, false, "unitless");
    f.number("wall_height", p.wall_height, 0.0f, kMax, true, "m");
    f.integer("seed", p.seed, 0, 0xffffffffLL);
    f.number("dt", p.dt, 0.0f, kMax, true, "s");
    f.integer("steps", p.steps, 1, std::numeric_limits<int>::max());
    // The pit is sized from the count: it must hold at least one sphere between its walls.
    if (!(0.5f * p.pit_width() > p.radius)) {
      f.fail("pour.radius", "a sphere of radius " + number_text(p.radius) + " m does not fit in the pit of " +
                                std::to_string(p.spheres) + " spheres (half width " +
                                number_text(0.5f * p.pit_width()) + " m); expected a smaller radius");
    }
  }
  if (const Json* solver = top.find("solver")) {
    Fields f(*solver, "solver", source,
             {"substeps", "push_out_rate", "push_out_speed", "restitution_threshold", "linear_damping",
              "angular_damping", "narrowphase", "sleeping", "sleep_speed", "sleep_time", "wake_speed"});
    SolverSettings& v = s.solver;
    f.integer("substeps", v.substeps, 1, 64);
    f.number("push_out_rate", v.push_out_rate, 0.0f, 1.0f, true, "unitless");
    f.number("push_out_speed", v.push_out_speed, 0.0f, kMax, true, "m/s");
    f.number("restitution_threshold", v.restitution_threshold, 0.0f, kMax, false, "m/s");
    f.number("linear_damping", v.linear_damping, 0.0f, kMax, false, "1/s");
    f.number("angular_damping", v.angular_damping, 0.0f, kMax, false, "1/s");
    if (const Json* mode = f.find("narrowphase")) {
      if (!mode->is_string() || (*mode != "grid" && *mode != "naive"))
        f.fail("solver.narrowphase", "expected \"grid\" or \"naive\", got " + type_name(*mode));
      v.narrowphase = *mode == "naive" ? NarrowphaseMode::Naive : NarrowphaseMode::Grid;
    }
    f.boolean("sleeping", v.sleeping);
    f.number("sleep_speed", v.sleep_speed, 0.0f, kMax, false, "m/s");
    f.number("sleep_time", v.sleep_time, 0.0f, kMax, true, "s");
    f.number("wake_speed", v.wake_speed, 0.0f, kMax, false, "m/s");
  }
  top.vec3("gravity", s.gravity, "m/s^2");
  return s;
}

void apply_override(Json& j, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--set '" + assignment + "': expected key=value, e.g. pour.spheres=5000");
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  // The path must name a field of a complete scene (all keys present in the default's JSON).
  const Json defaults = scene_to_json(SceneFile{});
  const Json* known = &defaults;
  Json* target = &j;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    const std::string key = path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    if (!known->is_object() || !known->contains(key))
      throw Error("--set '" + assignment + "': '" + path.substr(0, dot) + "' is not a field of a scene file");
    known = &(*known)[key];
    if (!target->is_object()) *target = Json::object();
    target = &(*target)[key];
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  Json value = Json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;  // a bare word is a string: narrowphase=naive
  *target = std::move(value);
}

SceneFile load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  Json j;
  std::string source = path.empty() ? "the default scene" : path;
  if (path.empty()) {
    j = scene_to_json(SceneFile{});
  } else {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open the scene file");
    try {
      j = Json::parse(in);
    } catch (const Json::parse_error& e) {
      throw Error(path + ": not valid JSON (" + e.what() + ")");
    }
  }
  for (const std::string& o : overrides) apply_override(j, o);
  if (!overrides.empty()) source += " with --set overrides";
  return parse_scene(j, source);
}

void build_scene(const SceneFile& scene, World& world) {
  scene.pour.build(world);
  world.solver = scene.solver;
  world.set_gravity(scene.gravity);
  world.validate_settings();
}

}  // namespace ballpit
