// The canonical "pit-character" scene of shared/SCENES.md, in one place so the test, the
// benchmarks and the headless runner build the same scene: the pour scene, settled, plus the
// default character (Testwuson.X, 1.8 m tall) walking a scripted path for 10 s: 3 s walk
// forward, 2 s walk turning left (at the controller's 90 deg/s: a half turn), 3 s run
// forward, 2 s idle. It starts at the back of the room it has, facing +z.
// Decisions, each forced by the character being kinematic (it pushes, nothing pushes back):
// - The character stands in the pit while the balls pour and settle around it, and its script
//   starts after settling: spawned into a settled pile it would start with balls inside it.
// - The pit is the pour pit, widened only where the character's footprint circle would not fit
//   between the walls (the Wuson's reaches 2.27 m from its root: a 4.73 m pit, the pour's
//   below about 40,000 balls). N stays as asked, so the balls settle shallower there (0.2 m
//   at 10,000), and the root has no room to move: the character walks, turns and runs in
//   place. At 100,000 balls (7.5 m) it has 2.7 m to walk in, at 1,000,000 (23.7 m) 19 m.
// - The character is lifted so its colliders stay foot_clearance_r ball radii above the floor
//   in every pose, so a hoof never pins a ball against the floor: two immovable surfaces
//   closer than a ball's diameter leave it nowhere to go, and one must then overlap it.
#pragma once

#include <memory>
#include <vector>

#include "engine/character.h"
#include "engine/entity.h"
#include "engine/pour_scene.h"
#include "systems/character_pipeline.h"

namespace ballpit {

class Scheduler;
class World;

struct PitCharacterScene {
  PourScene pour;            // N, radius, mass, materials, step: shared/SCENES.md's pour
  CharacterDesc character;   // the Wuson, 1.8 m, capsule colliders
  int settle_steps = 300;    // SCENES.md calls the pour settled from its step 300
  float foot_clearance_r = 2.2f;  // the lattice spacing: a ball fits under a hoof with 10% to spare
  std::vector<ScriptSegment> path = scripted_path();

  static std::vector<ScriptSegment> scripted_path();

  // Pit, balls and character, standing idle at the start of its path (the back of the room it
  // has, facing +z). Balls fill the pour's jittered lattice layer by layer, skipping lattice
  // points inside the character. Returns the character.
  Entity build(World& world, std::shared_ptr<const Model> model = nullptr) const;
  // Runs the settle steps on a scheduler that has the physics and character systems.
  void settle(World& world, Scheduler& scheduler) const;
  // Hands the character its script: the path starts with the next step.
  void start_path(World& world, Entity who) const;
};

// The rules above for one character in a pit that is already configured (scene files with a
// character use them too): spawned, the pit widened where its footprint circle would not fit,
// standing at the back of the room it has, facing +z, lifted so its lowest collider in any
// pose is `clearance` (unit: m) above the floor. Returns the character.
Entity spawn_pit_character(World& world, std::shared_ptr<const Model> model, const CharacterDesc& desc,
                           float clearance);

// Whether a ball of `radius` at p would start inside a joint collider, or within 0.1 radius of
// one (so none starts in a speculative contact with the character).
bool inside_character(const World& world, const Vec3& p, float radius);

}  // namespace ballpit
