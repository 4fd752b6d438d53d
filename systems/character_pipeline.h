// The character as a whole: spawning one (import, gait measurement, collider fitting, rows in
// the joint-collider table) and the systems that move it each step, in pipeline order:
// controller -> animation -> joint colliders, skinning palette. Add them before the physics
// systems, so the colliders are in place when the narrowphase looks for them.
// Decision: a world without characters schedules none of these systems and has no collider
// rows ("model only what a scene needs").
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/character.h"
#include "engine/entity.h"
#include "engine/model_import.h"

namespace ballpit {

class Scheduler;
class World;

struct CharacterDesc {
  std::string model_path = kDefaultModelPath;
  float height = 1.8f;  // the model is scaled uniformly so its bind pose is this tall (unit: m)
  float scale = 0.0f;   // model units -> m; when > 0 it replaces `height` (a scene file may give either)
  std::string idle_clip = marine::kIdleClip;
  std::string walk_clip = marine::kWalkClip;
  std::string run_clip = marine::kRunClip;
  // One-shot actions the controller may trigger (engine/character.h's ActionRole); empty: the
  // model has none, and the input to play it is ignored.
  std::string jump_clip = marine::kJumpClip;
  std::string kick_clip = marine::kKickClip;
  Vec3 forward = Vec3::UnitZ();  // the model's facing axis in its own space (both models face +z)
  ColliderKind colliders = ColliderKind::Capsules;
  // Root: x and z place the pivot (the centre of the bind pose's footprint) on the floor; y
  // lifts the character's lowest bind-pose point that far above the floor (unit: m).
  Vec3 position = Vec3::Zero();
  float heading = 0.0f;  // (unit: rad), 0 faces +z, positive turns left
  ControllerSettings controller;

  // The second model: Debian's Testwuson.X with its clips, which has no actions.
  static CharacterDesc wuson();
};

// Spawns a character: imports the model (or uses the one given), checks the clips, measures
// gaits, fits colliders and adds their rows. Throws ballpit::Error naming the model file and
// the clip or setting at fault.
Entity add_character(World& world, const CharacterDesc& desc);
Entity add_character(World& world, std::shared_ptr<const Model> model, const CharacterDesc& desc);

// Moves a character to `root` at once (a teleport): pose, palettes and collider rows follow,
// with zero surface velocity. Its script, phase and foot-slip record are kept.
void place_character(World& world, Entity character, const RootState& root);

// Adds the character systems when the world has characters; nothing otherwise.
void add_character_systems(Scheduler& scheduler, const World& world);

// Names of the systems add_character_systems adds (for per-system cost reports).
const std::vector<std::string_view>& character_system_names();

}  // namespace ballpit
