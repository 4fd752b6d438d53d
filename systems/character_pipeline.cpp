#include "systems/character_pipeline.h"

#include <cmath>

#include "engine/error.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/animation.h"
#include "systems/character_controller.h"
#include "systems/joint_colliders.h"
#include "systems/locomotion.h"
#include "systems/skinning.h"

namespace ballpit {

namespace {

// A walk or run cycle whose planted foot slides more than this per metre travelled at its best
// speed is not a locomotion cycle. The Wuson's slide about 0.25; a clip that does not step
// (a fit, a wave) slides nearly 1: its feet do not push the body along at all.
constexpr float kMaxGaitSlip = 0.6f;

[[noreturn]] void fail(const Model& model, const std::string& what) {
  throw Error("character from model file '" + model.path + "': " + what);
}

}  // namespace

CharacterDesc CharacterDesc::wuson() {
  CharacterDesc d;
  d.model_path = kWusonModelPath;
  d.idle_clip = "Wuson_Bind";
  d.walk_clip = "Wuson_Walk";
  d.run_clip = "Wuson_Run";
  d.jump_clip.clear();
  d.kick_clip.clear();
  return d;
}

Entity add_character(World& world, const CharacterDesc& desc) {
  return add_character(world, load_model(desc.model_path), desc);
}

Entity add_character(World& world, std::shared_ptr<const Model> model, const CharacterDesc& desc) {
  if (!model) throw Error("add_character: no model");
  const Model& m = *model;
  const bool by_scale = desc.scale > 0.0f;
  if (by_scale ? !std::isfinite(desc.scale) : (!(desc.height > 0.0f) || !std::isfinite(desc.height)))
    fail(m, by_scale ? "scale must be a finite number > 0, got " + std::to_string(desc.scale)
                     : "height must be a finite number > 0 m, got " + std::to_string(desc.height));
  if (!by_scale && !(m.bind_height() > 0.0f)) fail(m, "its bind pose is flat (height 0), so it cannot be scaled to a height");
  if (!all_finite(desc.position) || !std::isfinite(desc.heading)) fail(m, "position and heading must be finite");
  const Vec3 flat(desc.forward.x(), 0.0f, desc.forward.z());
  if (!(flat.norm() > 0.0f) || !all_finite(flat)) fail(m, "forward axis must have a horizontal (x, z) part");

  CharacterSetup setup;
  setup.model = model;
  setup.scale = by_scale ? desc.scale : desc.height / m.bind_height();
  // The pivot is the centre of the bind pose's footprint, at its lowest point.
  setup.pivot = Vec3(0.5f * (m.bind_min.x() + m.bind_max.x()), m.bind_min.y(), 0.5f * (m.bind_min.z() + m.bind_max.z()));
  setup.forward = flat.normalized();
  const std::string* names[kRoles] = {&desc.idle_clip, &desc.walk_clip, &desc.run_clip};
  for (int role = 0; role < kRoles; ++role) setup.clips[role] = static_cast<std::uint32_t>(m.clip_index(*names[role]));
  const std::string* action_names[kActions] = {&desc.jump_clip, &desc.kick_clip};
  for (int action = 0; action < kActions; ++action)
    if (!action_names[action]->empty())
      setup.actions[static_cast<std::size_t>(action)] = static_cast<std::int32_t>(m.clip_index(*action_names[action]));
  setup.feet = find_feet(m);
  for (int role = kWalk; role < kRoles; ++role)
    setup.gaits[role] = measure_gait(m, setup.clips[role], setup.feet, setup.scale, setup.forward);
  const Gait& walk = setup.gaits[kWalk];
  const Gait& run = setup.gaits[kRun];
  for (int role = kWalk; role < kRoles; ++role) {
    const Gait& g = setup.gaits[role];
    if (!(g.speed > 0.0f) || !(g.slip < kMaxGaitSlip))
      fail(m, std::string(role == kWalk ? "walk" : "run") + " clip '" + *names[role] +
                  "' is not a locomotion cycle: at its best ground speed (" + std::to_string(g.speed) +
                  " m/s) its planted foot still slides " + std::to_string(static_cast<int>(100.0f * g.slip)) +
                  "% of the distance");
  }
  if (!(run.speed > walk.speed))
    fail(m, "run clip '" + desc.run_clip + "' (gait speed " + std::to_string(run.speed) +
                " m/s) must be faster than walk clip '" + desc.walk_clip + "' (" + std::to_string(walk.speed) + " m/s)");

  setup.controller = desc.controller;
  ControllerSettings& c = setup.controller;
  if (c.walk_speed <= 0.0f) c.walk_speed = walk.speed;
  if (c.run_speed <= 0.0f) c.run_speed = run.speed;
  if (c.back_speed <= 0.0f) c.back_speed = c.walk_speed;
  if (!std::isfinite(c.walk_speed + c.run_speed + c.back_speed + c.turn_rate + c.acceleration + c.wall_clearance) ||
      !(c.turn_rate >= 0.0f) || !(c.acceleration > 0.0f) || !(c.wall_clearance >= 0.0f) ||
      !(c.blend_time > 0.0f) || !std::isfinite(c.blend_time))
    fail(m, "controller settings must be finite, turn_rate >= 0 rad/s, acceleration > 0 m/s^2, "
            "wall_clearance >= 0 m, blend_time > 0 s");

  setup.collider_kind = desc.colliders;
  setup.shapes = fit_bone_shapes(m, desc.colliders);
  if (setup.shapes.empty()) fail(m, "no bone drives enough vertices to fit a joint collider");
  const ColliderReach reach = collider_reach(setup);
  setup.footprint_radius = reach.footprint_radius;
  setup.lowest_collider = reach.lowest;

  // Everything is checked: from here on nothing throws, so a failed spawn leaves no trace.
  const Entity e = world.entities.create();
  setup.entity = e;
  setup.first_collider = static_cast<std::uint32_t>(world.colliders.size());
  for (const BoneShape& s : setup.shapes) {
    ColliderDesc d;
    d.shape = s.a == s.b ? ColliderShape::Sphere : ColliderShape::Capsule;
    d.a = d.b = desc.position;  // placed below
    d.radius = s.radius * setup.scale;
    d.owner = e;
    d.bone = s.joint;
    world.colliders.add(d);
  }
  world.characters.add(std::move(setup), CharacterMotion{}, CharacterPose{});
  RootState root;
  root.position = desc.position;
  root.heading = desc.heading;
  place_character(world, e, root);
  return e;
}

void place_character(World& world, Entity character, const RootState& root) {
  const int i = world.characters.find(character);
  if (i < 0) throw Error("place_character: " + to_string(character) + " is not a character");
  if (!all_finite(root.position) || !std::isfinite(root.heading) || !std::isfinite(root.speed))
    throw Error("place_character: " + to_string(character) + ": root must be finite");
  const std::size_t row = static_cast<std::size_t>(i);
  const CharacterSetup& setup = world.characters.setup(row);
  CharacterMotion& motion = world.characters.mut_motion(row);
  motion.current = root;
  motion.previous = root;
  CharacterPose& pose = world.characters.mut_pose(row);
  reset_pose(setup, motion, pose);
  const Affine3 w = character_transform(setup, root);
  const std::vector<SkinnedMesh>& meshes = setup.model->meshes;
  pose.palettes.resize(meshes.size());
  for (std::size_t k = 0; k < meshes.size(); ++k) skinning_palette(meshes[k], pose.model, w, pose.palettes[k]);
  for (std::size_t k = 0; k < setup.shapes.size(); ++k) {
    const BoneShape& s = setup.shapes[k];
    const Affine3 m = w * pose.model[s.joint];
    world.colliders.set_pose(setup.first_collider + static_cast<std::uint32_t>(k), m * s.a, m * s.b, Vec3::Zero(),
                             Vec3::Zero());
  }
}

void add_character_systems(Scheduler& scheduler, const World& world) {
  if (world.characters.size() == 0) return;
  scheduler.emplace<CharacterControllerSystem>();
  scheduler.emplace<AnimationSystem>();
  scheduler.emplace<JointColliderSystem>();
  scheduler.emplace<SkinningSystem>();
}

const std::vector<std::string_view>& character_system_names() {
  static const std::vector<std::string_view> names = {"character_controller", "animation", "joint_colliders",
                                                      "skinning"};
  return names;
}

}  // namespace ballpit
