#include "systems/scene_setup.h"

#include <algorithm>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/model_import.h"
#include "engine/populations.h"
#include "engine/world.h"
#include "systems/pit_character_scene.h"

namespace ballpit {

namespace {

constexpr const char* kRoleNames[kRoles] = {"idle", "walk", "run"};

// The model's clips must include the three the scene names; checked before spawning so the
// message names the scene file and the field, not only the model.
void check_clips(const SceneCharacter& c, const Model& model, const std::string& source) {
  for (int role = 0; role < kRoles; ++role) {
    const std::string& name = c.clips[static_cast<std::size_t>(role)];
    std::string known;
    bool found = false;
    for (const Clip& clip : model.clips) {
      found = found || clip.name == name;
      known += (known.empty() ? "'" : ", '") + clip.name + "'";
    }
    if (!found)
      throw Error(source + ": character.clips." + kRoleNames[role] + ": expected a clip of model file '" + model.path +
                  "' (its clips: " + known + "), got '" + name + "'");
  }
}

}  // namespace

CharacterDesc character_desc(const SceneCharacter& c) {
  CharacterDesc d;
  d.model_path = c.model;
  d.height = c.height;
  d.scale = c.scale;
  d.idle_clip = c.clips[kIdle];
  d.walk_clip = c.clips[kWalk];
  d.run_clip = c.clips[kRun];
  d.forward = c.forward;
  d.colliders = c.colliders;
  d.controller = c.controller;
  return d;
}

SceneSetup setup_scene(const SceneFile& scene, World& world, std::shared_ptr<const Model> model) {
  SceneSetup out;
  if (!scene.uses_character()) {
    build_scene(scene, world);
    return out;
  }
  const SceneCharacter& c = *scene.character;
  if (!model) {
    try {
      model = import_model(c.model);
    } catch (const Error& e) {
      throw Error(scene.source + ": character.model: " + e.what());
    }
  }
  check_clips(c, *model, scene.source);
  configure_scene(scene, world);
  // The canonical scene lifts the character foot_clearance_r radii of its (one) ball size; with
  // several sizes the largest ball must fit under a hoof.
  float largest = 0.0f;
  for (const Population& p : scene.populations) largest = std::max(largest, p.radius.largest());
  try {
    out.character = spawn_pit_character(world, std::move(model), character_desc(c), c.foot_clearance_r * largest);
  } catch (const Error& e) {
    throw Error(scene.source + ": character: " + e.what());
  }
  add_populations(world, scene.populations, scene.seed, scene.source,
                  [&world](const Vec3& p, float r) { return inside_character(world, p, r); });
  out.settle_steps = c.settle_steps;
  if (c.scripted) out.path = c.path;
  return out;
}

void settle_scene(const SceneSetup& setup, World& world, Scheduler& scheduler) {
  if (!setup.character.valid()) return;
  FixedStepLoop loop(world, scheduler);
  for (int s = 0; s < setup.settle_steps; ++s) loop.step();
}

void start_scene_path(const SceneSetup& setup, World& world) {
  if (!setup.character.valid()) return;
  const int i = world.characters.find(setup.character);
  if (i < 0) throw Error("start_scene_path: " + to_string(setup.character) + " is not a character");
  CharacterMotion& motion = world.characters.mut_motion(static_cast<std::size_t>(i));
  motion.script = setup.path;
  motion.script_time = 0.0f;
}

}  // namespace ballpit
