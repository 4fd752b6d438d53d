// A scene file built into a world, character included: the pit, materials and populations
// (engine/scene_file.h, engine/populations.h) and, when the scene uses one, its character by
// the pit-character rules (systems/pit_character_scene.h), with no ball spawned inside it.
// Reads: the scene and the character's model file. Writes: a fresh World.
// Decision: only what the scene uses is made. Without a character there are no character or
// joint-collider rows, so add_character_systems schedules nothing; without friction (unless
// stated) no angular column; without sleeping no wake or sleep system.
#pragma once

#include <memory>
#include <vector>

#include "engine/character.h"
#include "engine/entity.h"
#include "engine/model.h"
#include "engine/scene_file.h"
#include "systems/character_pipeline.h"

namespace ballpit {

class Scheduler;
class World;

struct SceneSetup {
  Entity character;                 // invalid when the scene uses none
  int settle_steps = 0;             // steps the balls settle before the path starts
  std::vector<ScriptSegment> path;  // empty: player control (idle in a headless run)
};

// The spawn description of a scene's character (its placement is the pit-character rule's).
CharacterDesc character_desc(const SceneCharacter& c);

// Builds the scene into an empty world. `model` saves importing the character's model file
// again. Throws ballpit::Error "SOURCE: FIELD: ..." naming the scene, e.g. for a clip the model
// does not have: "scene.json: character.clips.walk: expected a clip of model file ...".
SceneSetup setup_scene(const SceneFile& scene, World& world, std::shared_ptr<const Model> model = nullptr);

// Runs the settle steps (none without a character), then hands the character its path.
void settle_scene(const SceneSetup& setup, World& world, Scheduler& scheduler);
void start_scene_path(const SceneSetup& setup, World& world);

}  // namespace ballpit
