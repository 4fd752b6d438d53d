// Player controls: which keys are held becomes the character's controller input. The viewer
// fills KeyState from GLFW each frame; tests fill it by hand, so simulated key presses go
// through exactly the mapping a player's do.
// Decision: arrows and WASD are equivalent (either may be held); Shift turns a walk into a run;
// Space jumps and K kicks (held, the action repeats as each one ends).
#pragma once

#include "engine/character.h"

namespace ballpit {

struct KeyState {
  bool forward = false;  // W or Up
  bool back = false;     // S or Down
  bool left = false;     // A or Left
  bool right = false;    // D or Right
  bool run = false;      // Shift
  bool jump = false;     // Space
  bool kick = false;     // K
};

ControllerInput controller_input(const KeyState& keys);

}  // namespace ballpit
