#include "engine/character_snapshot.h"

#include <cmath>

#include "engine/error.h"
#include "engine/model_import.h"
#include "engine/snapshot_io.h"
#include "engine/world.h"

namespace ballpit {

namespace {

using snapshot_io::Reader;
using snapshot_io::Writer;

// A new field in these structs must be written and read below: these asserts fail the build
// until it is (and snapshot.cpp's kVersion is bumped).
static_assert(sizeof(Gait) == 24 && sizeof(ControllerSettings) == 28, "Gait or ControllerSettings changed: update character_snapshot.cpp");
static_assert(sizeof(ControllerInput) == 12 && sizeof(ScriptSegment) == 16 && sizeof(RootState) == 20,
              "ControllerInput, ScriptSegment or RootState changed: update character_snapshot.cpp");
static_assert(sizeof(BoneShape) == 32 && sizeof(FootSlip) == 40, "BoneShape or FootSlip changed: update character_snapshot.cpp");
static_assert(sizeof(CharacterSetup) == 240 && sizeof(CharacterMotion) == 88 && sizeof(CharacterPose) == 864,
              "a character struct changed: update character_snapshot.cpp");

void put_input(Writer& w, const ControllerInput& in) {
  w.put(in.forward);
  w.put(in.turn);
  w.put(static_cast<std::uint8_t>(in.run));
  w.put(static_cast<std::uint8_t>(in.jump));
  w.put(static_cast<std::uint8_t>(in.kick));
}

// Format 4 added the actions (jump, kick); an older file has none.
ControllerInput get_input(Reader& r, std::uint32_t version) {
  ControllerInput in;
  in.forward = r.get<float>("character.input.forward");
  in.turn = r.get<float>("character.input.turn");
  in.run = r.get<std::uint8_t>("character.input.run") != 0;
  if (version >= 4) {
    in.jump = r.get<std::uint8_t>("character.input.jump") != 0;
    in.kick = r.get<std::uint8_t>("character.input.kick") != 0;
  }
  return in;
}

// Gait as format 3 held it (speed, cycle, touchdown, slip), the figures added since measured
// again only where a report asks (they steer nothing).
void put_gait(Writer& w, const Gait& g) {
  w.put(g.speed);
  w.put(g.cycle);
  w.put(g.touchdown);
  w.put(g.slip);
}
Gait get_gait(Reader& r) {
  Gait g;
  g.speed = r.get<float>("character.gaits");
  g.cycle = r.get<float>("character.gaits");
  g.touchdown = r.get<float>("character.gaits");
  g.slip = r.get<float>("character.gaits");
  return g;
}

void put_root(Writer& w, const RootState& root) {
  w.put(root.position);
  w.put(root.heading);
  w.put(root.speed);
}

RootState get_root(Reader& r) {
  RootState root;
  root.position = r.get<Vec3>("character.root.position");
  root.heading = r.get<float>("character.root.heading");
  root.speed = r.get<float>("character.root.speed");
  return root;
}

bool finite_root(const RootState& r) { return all_finite(r.position) && std::isfinite(r.heading) && std::isfinite(r.speed); }

bool finite_input(const ControllerInput& in) { return std::isfinite(in.forward) && std::isfinite(in.turn); }

// Checks one character against its model and the restored world, so the systems that step it
// never index past a skeleton or a collider row.
void check_character(const CharacterSnapshot& c, const Model& m, const World& w, const std::string& at) {
  auto fail = [&](const std::string& what) { throw Error(at + ": " + what); };
  const CharacterSetup& s = c.setup;
  const std::size_t joints = m.skeleton.size();
  for (int role = 0; role < kRoles; ++role) {
    const std::uint32_t clip = s.clips[static_cast<std::size_t>(role)];
    const std::string& name = c.clip_names[static_cast<std::size_t>(role)];
    if (clip >= m.clips.size() || m.clips[clip].name != name)
      fail("model file '" + m.path + "' has no clip '" + name + "' at index " + std::to_string(clip) +
           "; expected the model file the snapshot was saved with");
  }
  if (!w.entities.alive(s.entity) || w.spheres.contains(s.entity))
    fail(to_string(s.entity) + " is not a live entity of its own in the registry");
  if (!(s.scale > 0.0f) || !std::isfinite(s.scale) || !all_finite(s.pivot) || !all_finite(s.forward) ||
      !std::isfinite(s.footprint_radius) || !std::isfinite(s.lowest_collider))
    fail("setup holds a non-finite or non-positive value (scale must be > 0)");
  // What add_character guarantees, so the locomotion maths (strides, phase rates) never
  // divides by zero: walk and run gaits with positive speed and cycle, run faster than walk.
  for (const Gait& g : s.gaits)
    if (!std::isfinite(g.speed) || !std::isfinite(g.cycle) || !(g.touchdown >= 0.0f && g.touchdown <= 1.0f) ||
        !std::isfinite(g.slip))
      fail("a gait holds a non-finite value or a touchdown outside [0, 1]");
  const Gait& walk = s.gaits[kWalk];
  const Gait& run = s.gaits[kRun];
  if (!(walk.speed > 0.0f && walk.cycle > 0.0f && run.cycle > 0.0f && run.speed > walk.speed))
    fail("walk and run gaits must have speed and cycle > 0, run faster than walk");
  const ControllerSettings& ctl = s.controller;
  if (!std::isfinite(ctl.walk_speed + ctl.run_speed + ctl.back_speed + ctl.turn_rate + ctl.acceleration + ctl.wall_clearance) ||
      !(ctl.walk_speed > 0.0f && ctl.run_speed > 0.0f && ctl.back_speed > 0.0f) || !(ctl.turn_rate >= 0.0f) ||
      !(ctl.acceleration > 0.0f) || !(ctl.wall_clearance >= 0.0f) || !(ctl.blend_time > 0.0f) ||
      !std::isfinite(ctl.blend_time))
    fail("controller settings must be finite, speeds, acceleration and blend_time > 0, turn_rate and wall_clearance >= 0");
  for (std::uint16_t f : s.feet)
    if (f >= joints) fail("foot joint " + std::to_string(f) + " is not in the model's " + std::to_string(joints) + " joints");
  for (const BoneShape& b : s.shapes)
    if (b.joint >= joints || !all_finite(b.a) || !all_finite(b.b) || !(b.radius > 0.0f) || !std::isfinite(b.radius))
      fail("collider shape of joint " + std::to_string(b.joint) + " is invalid (joint out of range or bad geometry)");
  if (static_cast<std::size_t>(s.first_collider) + s.shapes.size() > w.colliders.size())
    fail("its collider rows [" + std::to_string(s.first_collider) + ", " +
         std::to_string(s.first_collider + s.shapes.size()) + ") are not all in the " +
         std::to_string(w.colliders.size()) + " collider rows");

  const CharacterMotion& mo = c.motion;
  if (!finite_input(mo.input) || !std::isfinite(mo.script_time) || !finite_root(mo.previous) || !finite_root(mo.current))
    fail("controller state holds a non-finite value");
  for (const ScriptSegment& seg : mo.script)
    if (!std::isfinite(seg.duration) || !finite_input(seg.input)) fail("script holds a non-finite value");

  const CharacterPose& p = c.pose;
  if (!(p.phase >= 0.0f && p.phase < 1.0f) || !(p.idle_time >= 0.0f) || !std::isfinite(p.idle_time))
    fail("pose phase must be in [0, 1) and the idle clock finite and >= 0");
  for (float wgt : p.weights)
    if (!(wgt >= 0.0f) || !std::isfinite(wgt)) fail("pose blend weights must be finite and >= 0");
  for (std::int32_t clip : c.setup.actions)
    if (clip < -1 || clip >= static_cast<std::int32_t>(m.clips.size()))
      fail("an action names clip " + std::to_string(clip) + ", which the model does not have");
  if (p.action < -1 || p.action >= kActions || (p.action >= 0 && c.setup.actions[static_cast<std::size_t>(p.action)] < 0) ||
      !(p.action_time >= 0.0f) || !std::isfinite(p.action_time))
    fail("the action playing must be one the character has, at a finite time >= 0");
  auto joints_sized = [&](std::size_t n, const char* what) {
    if (n != joints)
      fail(std::string(what) + " has " + std::to_string(n) + " joints, expected the model's " + std::to_string(joints));
  };
  joints_sized(p.action_cursor.translation.size(), "pose.action_cursor");
  joints_sized(p.action_cursor.rotation.size(), "pose.action_cursor");
  joints_sized(p.action_cursor.scale.size(), "pose.action_cursor");
  for (const ClipCursor& cur : p.cursors) {
    joints_sized(cur.translation.size(), "pose.cursors");
    joints_sized(cur.rotation.size(), "pose.cursors");
    joints_sized(cur.scale.size(), "pose.cursors");
  }
  joints_sized(p.local.translation.size(), "pose.local");
  joints_sized(p.local.rotation.size(), "pose.local");
  joints_sized(p.local.scale.size(), "pose.local");
  joints_sized(p.model.size(), "pose.model");
  joints_sized(p.model_previous.size(), "pose.model_previous");
  if (p.palettes.size() != m.meshes.size())
    fail("pose has " + std::to_string(p.palettes.size()) + " skinning palettes, expected one per mesh (" +
         std::to_string(m.meshes.size()) + ")");
  for (std::size_t k = 0; k < m.meshes.size(); ++k)
    if (p.palettes[k].size() != m.meshes[k].inverse_bind.size())
      fail("skinning palette " + std::to_string(k) + " has the wrong number of bones");
}

}  // namespace

void capture_characters(const World& world, std::vector<CharacterSnapshot>& out, ColliderSnapshot& colliders) {
  const CharacterTable& t = world.characters;
  out.resize(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    CharacterSnapshot& c = out[i];
    c.setup = t.setup(i);
    // A model assembled from clip sources is named by its recipe (engine/clip_sources.h).
    c.model_path = !c.setup.model ? std::string()
                   : c.setup.model->load_name.empty() ? c.setup.model->path
                                                      : c.setup.model->load_name;
    for (int role = 0; role < kRoles; ++role) {
      const std::uint32_t clip = c.setup.clips[static_cast<std::size_t>(role)];
      c.clip_names[static_cast<std::size_t>(role)] =
          c.setup.model && clip < c.setup.model->clips.size() ? c.setup.model->clips[clip].name : std::string();
    }
    c.motion = t.motion(i);
    c.pose = t.pose(i);
    for (LocalPose& scratch : c.pose.samples) scratch = LocalPose{};
  }
  const ColliderTable& k = world.colliders;
  colliders.shape.resize(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) colliders.shape[i] = static_cast<std::uint8_t>(k.shape()[i]);
  colliders.a.assign(k.a().begin(), k.a().end());
  colliders.b.assign(k.b().begin(), k.b().end());
  colliders.radius.assign(k.radius().begin(), k.radius().end());
  colliders.velocity_a.assign(k.velocity_a().begin(), k.velocity_a().end());
  colliders.velocity_b.assign(k.velocity_b().begin(), k.velocity_b().end());
  colliders.owner_index.resize(k.size());
  colliders.owner_generation.resize(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) {
    colliders.owner_index[i] = k.owner()[i].index;
    colliders.owner_generation[i] = k.owner()[i].generation;
  }
  colliders.bone.assign(k.bone().begin(), k.bone().end());
}

void put_characters(Writer& w, const std::vector<CharacterSnapshot>& characters, const ColliderSnapshot& k) {
  w.array(k.shape);
  w.array(k.a);
  w.array(k.b);
  w.array(k.radius);
  w.array(k.velocity_a);
  w.array(k.velocity_b);
  w.array(k.owner_index);
  w.array(k.owner_generation);
  w.array(k.bone);
  w.put(static_cast<std::uint64_t>(characters.size()));
  for (const CharacterSnapshot& c : characters) {
    w.text(c.model_path);
    for (const std::string& name : c.clip_names) w.text(name);
    const CharacterSetup& s = c.setup;
    w.put(s.entity.index);
    w.put(s.entity.generation);
    for (std::uint32_t clip : s.clips) w.put(clip);
    for (const Gait& g : s.gaits) put_gait(w, g);
    for (std::int32_t a : s.actions) w.put(a);
    w.put(s.scale);
    w.put(s.pivot);
    w.put(s.forward);
    w.array(s.feet);
    w.put(s.controller);
    w.put(s.footprint_radius);
    w.put(s.lowest_collider);
    w.put(static_cast<std::uint8_t>(s.collider_kind));
    w.put(static_cast<std::uint64_t>(s.shapes.size()));
    for (const BoneShape& b : s.shapes) {
      w.put(b.joint);
      w.put(b.a);
      w.put(b.b);
      w.put(b.radius);
    }
    w.put(s.first_collider);

    const CharacterMotion& m = c.motion;
    put_input(w, m.input);
    w.put(static_cast<std::uint64_t>(m.script.size()));
    for (const ScriptSegment& seg : m.script) {
      w.put(seg.duration);
      put_input(w, seg.input);
    }
    w.put(m.script_time);
    put_root(w, m.previous);
    put_root(w, m.current);

    const CharacterPose& p = c.pose;
    w.put(p.phase);
    w.put(p.idle_time);
    for (float wgt : p.weights) w.put(wgt);
    for (const ClipCursor& cur : p.cursors) {
      w.array(cur.translation);
      w.array(cur.rotation);
      w.array(cur.scale);
    }
    w.put(p.action);
    w.put(p.action_time);
    w.array(p.action_cursor.translation);
    w.array(p.action_cursor.rotation);
    w.array(p.action_cursor.scale);
    w.array(p.local.translation);
    w.array(p.local.rotation);
    w.array(p.local.scale);
    w.array(p.model_previous);
    w.array(p.model);
    w.put(static_cast<std::uint64_t>(p.palettes.size()));
    for (const std::vector<Mat4>& palette : p.palettes) w.array(palette);
    w.put(p.slip.sum);
    w.put(p.slip.lowest_sum);
    w.put(p.slip.ground_sum);
    w.put(p.slip.max);
    w.put(p.slip.samples);
  }
}

void get_characters(Reader& r, std::uint32_t version, std::vector<CharacterSnapshot>& characters,
                    ColliderSnapshot& k) {
  r.array("colliders.shape", k.shape);
  r.array("colliders.a", k.a);
  r.array("colliders.b", k.b);
  r.array("colliders.radius", k.radius);
  r.array("colliders.velocity_a", k.velocity_a);
  r.array("colliders.velocity_b", k.velocity_b);
  r.array("colliders.owner_index", k.owner_index);
  r.array("colliders.owner_generation", k.owner_generation);
  r.array("colliders.bone", k.bone);
  const std::uint64_t count = r.count("characters.count", 64);
  characters.resize(static_cast<std::size_t>(count));
  for (CharacterSnapshot& c : characters) {
    c.model_path = r.text("character.model_path");
    for (std::string& name : c.clip_names) name = r.text("character.clip_name");
    CharacterSetup& s = c.setup;
    s.entity.index = r.get<std::uint32_t>("character.entity");
    s.entity.generation = r.get<std::uint32_t>("character.entity");
    for (std::uint32_t& clip : s.clips) clip = r.get<std::uint32_t>("character.clips");
    for (Gait& g : s.gaits) g = get_gait(r);
    if (version >= 4)
      for (std::int32_t& a : s.actions) a = r.get<std::int32_t>("character.actions");
    s.scale = r.get<float>("character.scale");
    s.pivot = r.get<Vec3>("character.pivot");
    s.forward = r.get<Vec3>("character.forward");
    r.array("character.feet", s.feet);
    s.controller = r.get<ControllerSettings>("character.controller");
    s.footprint_radius = r.get<float>("character.footprint_radius");
    s.lowest_collider = r.get<float>("character.lowest_collider");
    const auto kind = r.get<std::uint8_t>("character.collider_kind");
    if (kind > static_cast<std::uint8_t>(ColliderKind::Capsules)) r.fail("character.collider_kind is not a known kind");
    s.collider_kind = static_cast<ColliderKind>(kind);
    s.shapes.resize(static_cast<std::size_t>(r.count("character.shapes", 30)));
    for (BoneShape& b : s.shapes) {
      b.joint = r.get<std::uint16_t>("character.shape.joint");
      b.a = r.get<Vec3>("character.shape.a");
      b.b = r.get<Vec3>("character.shape.b");
      b.radius = r.get<float>("character.shape.radius");
    }
    s.first_collider = r.get<std::uint32_t>("character.first_collider");

    CharacterMotion& m = c.motion;
    m.input = get_input(r, version);
    m.script.resize(static_cast<std::size_t>(r.count("character.script", 13)));
    for (ScriptSegment& seg : m.script) {
      seg.duration = r.get<float>("character.script.duration");
      seg.input = get_input(r, version);
    }
    m.script_time = r.get<float>("character.script_time");
    m.previous = get_root(r);
    m.current = get_root(r);

    CharacterPose& p = c.pose;
    p.phase = r.get<float>("character.pose.phase");
    p.idle_time = r.get<float>("character.pose.idle_time");
    for (float& wgt : p.weights) wgt = r.get<float>("character.pose.weights");
    for (ClipCursor& cur : p.cursors) {
      r.array("character.pose.cursors", cur.translation);
      r.array("character.pose.cursors", cur.rotation);
      r.array("character.pose.cursors", cur.scale);
    }
    if (version >= 4) {
      p.action = r.get<std::int32_t>("character.pose.action");
      p.action_time = r.get<float>("character.pose.action_time");
      r.array("character.pose.action_cursor", p.action_cursor.translation);
      r.array("character.pose.action_cursor", p.action_cursor.rotation);
      r.array("character.pose.action_cursor", p.action_cursor.scale);
    } else {
      p.action_cursor = p.cursors[kIdle];  // sized for the model: no action plays
    }
    r.array("character.pose.local.translation", p.local.translation);
    r.array("character.pose.local.rotation", p.local.rotation);
    r.array("character.pose.local.scale", p.local.scale);
    r.array("character.pose.model_previous", p.model_previous);
    r.array("character.pose.model", p.model);
    p.palettes.resize(static_cast<std::size_t>(r.count("character.pose.palettes", 8)));
    for (std::vector<Mat4>& palette : p.palettes) r.array("character.pose.palette", palette);
    p.slip.sum = r.get<double>("character.pose.slip");
    p.slip.lowest_sum = r.get<double>("character.pose.slip");
    p.slip.ground_sum = r.get<double>("character.pose.slip");
    p.slip.max = r.get<float>("character.pose.slip");
    p.slip.samples = r.get<std::uint64_t>("character.pose.slip");
  }
}

void restore_characters(const std::vector<CharacterSnapshot>& characters, const ColliderSnapshot& k, World& w) {
  const std::size_t rows = k.shape.size();
  auto check_rows = [&](std::size_t size, const char* field) {
    if (size != rows)
      throw Error(std::string(field) + " has " + std::to_string(size) + " rows, expected " + std::to_string(rows));
  };
  check_rows(k.a.size(), "colliders.a");
  check_rows(k.b.size(), "colliders.b");
  check_rows(k.radius.size(), "colliders.radius");
  check_rows(k.velocity_a.size(), "colliders.velocity_a");
  check_rows(k.velocity_b.size(), "colliders.velocity_b");
  check_rows(k.owner_index.size(), "colliders.owner_index");
  check_rows(k.owner_generation.size(), "colliders.owner_generation");
  check_rows(k.bone.size(), "colliders.bone");
  for (std::size_t i = 0; i < rows; ++i) {
    if (k.shape[i] > static_cast<std::uint8_t>(ColliderShape::Capsule))
      throw Error("colliders row " + std::to_string(i) + ": shape " + std::to_string(k.shape[i]) + " is not a known shape");
    ColliderDesc d;
    d.shape = static_cast<ColliderShape>(k.shape[i]);
    d.a = k.a[i];
    d.b = k.b[i];
    d.radius = k.radius[i];
    d.velocity_a = k.velocity_a[i];
    d.velocity_b = k.velocity_b[i];
    d.owner = {k.owner_index[i], k.owner_generation[i]};
    d.bone = k.bone[i];
    w.colliders.add(d);  // validates the geometry, naming the row
  }
  for (std::size_t i = 0; i < characters.size(); ++i) {
    const CharacterSnapshot& c = characters[i];
    const std::string at = "characters[" + std::to_string(i) + "]";
    std::shared_ptr<const Model> model = c.setup.model;
    if (!model) {
      try {
        model = load_model(c.model_path);
      } catch (const Error& e) {
        throw Error(at + ": " + e.what());
      }
    }
    check_character(c, *model, w, at);
    if (w.characters.find(c.setup.entity) >= 0) throw Error(at + ": " + to_string(c.setup.entity) + " appears twice");
    CharacterSetup setup = c.setup;
    setup.model = std::move(model);
    w.characters.add(std::move(setup), c.motion, c.pose);
  }
}

}  // namespace ballpit
