#include "app/controls.h"

namespace ballpit {

ControllerInput controller_input(const KeyState& keys) {
  ControllerInput in;
  in.forward = static_cast<float>(keys.forward) - static_cast<float>(keys.back);
  in.turn = static_cast<float>(keys.left) - static_cast<float>(keys.right);  // +1 turns left
  in.run = keys.run;
  in.jump = keys.jump;
  in.kick = keys.kick;
  return in;
}

}  // namespace ballpit
