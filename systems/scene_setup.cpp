#include "systems/scene_setup.h"

#include <algorithm>

#include "engine/clip_sources.h"
#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/model_import.h"
#include "engine/populations.h"
#include "engine/world.h"
#include "systems/pit_character_scene.h"

namespace ballpit {

namespace {

// The clips the scene names as they are (plain names) must be clips of the model; checked
// before spawning so the message names the scene file and the field, not only the model. Clips
// from other sources were checked as the model was assembled (engine/clip_sources.h).
void check_clips(const SceneCharacter& c, const Model& model, const std::string& source) {
  for (int role = 0; role < kClipRoles; ++role) {
    const ClipSource& s = c.clips[static_cast<std::size_t>(role)];
    if (!s.plain() || s.clip.empty()) continue;
    std::string known;
    bool found = false;
    for (const Clip& clip : model.clips) {
      found = found || clip.name == s.clip;
      known += (known.empty() ? "'" : ", '") + clip.name + "'";
    }
    if (!found)
      throw Error(source + ": character.clips." + kClipRoleNames[static_cast<std::size_t>(role)] +
                  ": expected a clip of model file '" + model.path + "' (its clips: " + known + "), got '" + s.clip +
                  "'");
  }
}

}  // namespace

CharacterDesc character_desc(const SceneCharacter& c) {
  CharacterDesc d;
  // Clips from other sources play from the derived model, which load_model rebuilds by name.
  d.model_path = needs_assembly(c.clips) ? clip_sources_name(c.model, c.clips) : c.model;
  d.height = c.height;
  d.scale = c.scale;
  static_assert(kFirstActionRole == kRoles && kClipRoles == int{kRoles} + int{kActions},
                "clip roles: the locomotion roles, then the actions");
  std::string* names[kClipRoles] = {&d.idle_clip, &d.walk_clip, &d.run_clip, &d.jump_clip, &d.kick_clip};
  for (int role = 0; role < kClipRoles; ++role)
    *names[role] = role_clip_name(role, c.clips[static_cast<std::size_t>(role)]);
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
  const CharacterDesc desc = character_desc(c);
  if (needs_assembly(c.clips)) {
    // A model given is the skin, or the derived model itself (the app keeps it between builds).
    if (!model || model->load_name != desc.model_path) {
      try {
        model = assemble_model(c.model, c.clips, model && model->load_name.empty() ? model : nullptr);
      } catch (const Error& e) {
        throw Error(scene.source + ": " + e.what());
      }
    }
  } else if (!model) {
    try {
      model = load_model(c.model);
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
    out.character = spawn_pit_character(world, std::move(model), desc, c.foot_clearance_r * largest);
  } catch (const Error& e) {
    // A role's clip that cannot serve (not a cycle) is named in the message by its derived
    // name: the message names its field too.
    const std::string what = e.what();
    for (int role = 0; role < kClipRoles; ++role) {
      const ClipSource& s = c.clips[static_cast<std::size_t>(role)];
      if (!s.plain() && what.find("'" + role_clip_name(role, s) + "'") != std::string::npos)
        throw Error(scene.source + ": character.clips." + kClipRoleNames[static_cast<std::size_t>(role)] + ": " + what);
    }
    throw Error(scene.source + ": character: " + what);
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
