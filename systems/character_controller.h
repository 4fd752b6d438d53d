// Character controller: turns input (a player's, or the character's script) into root motion
// over one step: forward and back at walk or run speed, turning left and right, and the whole
// character kept inside the pit walls.
// Reads: the pit. Writes: CharacterController (input from the script, root at both ends of the
// step).
// Decision: the character is kinematic and gravity never acts on it: its height is whatever
// it was placed at, so the balls' gravity may change at any time (World::set_gravity) without
// moving it. Ground speed follows the input through an acceleration limit, so the locomotion
// blend never jumps; a wall stops the root but not the legs (a player pressing into a wall
// sees the character walk in place, and its feet slide then).
#pragma once

#include "engine/character.h"
#include "engine/settings.h"
#include "engine/system.h"

namespace ballpit {

// The input a script gives at `time` (unit: s): its segment's, or no input after the end.
ControllerInput scripted_input(const std::vector<ScriptSegment>& script, float time);

// Largest |x| and |z| the root may reach so the footprint circle stays `wall_clearance` inside
// the walls; 0 when the pit is too small for the character (it then stays centred) (unit: m).
float root_limit(const CharacterSetup& setup, const Pit& pit);

// One step of dt (unit: s): previous = current, then current advanced by the input.
void advance_controller(const CharacterSetup& setup, CharacterMotion& motion, const Pit& pit, float dt);

class CharacterControllerSystem : public System {
 public:
  std::string_view name() const override { return "character_controller"; }
  Access access() const override;
  void run(World& world) override;
};

}  // namespace ballpit
