#include "engine/fixed_step_loop.h"

#include <algorithm>

#include "engine/scheduler.h"
#include "engine/world.h"

namespace ballpit {

void FixedStepLoop::step() {
  world_.set_step(world_.step());  // revalidates: a caller may have poked the settings
  scheduler_.run_frame(world_);
  ++world_.step_count;
}

int FixedStepLoop::advance(double real_seconds) {
  const double dt = world_.step();
  accumulator_ += std::max(real_seconds, 0.0);
  int taken = 0;
  while (accumulator_ >= dt && taken < max_catch_up) {
    step();
    accumulator_ -= dt;
    ++taken;
  }
  if (accumulator_ >= dt) accumulator_ = std::min(accumulator_, dt * 0.999);  // drop the hitch
  return taken;
}

float FixedStepLoop::alpha() const {
  return static_cast<float>(accumulator_ / static_cast<double>(world_.step()));
}

}  // namespace ballpit
