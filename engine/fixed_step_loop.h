// The fixed-step loop: physics always advances by the world's dt, however long a frame took.
// Real time accumulates; whole steps are taken from it, at most max_catch_up per call, so a
// long hitch (a debugger pause, a slow frame) drops time instead of spiralling into ever more
// catch-up steps. What is left over is the interpolation fraction for rendering.
// A step whose motion is too fast for a capped speculative margin runs as several passes of
// every system (engine/step_passes.h); systems see each pass's length as world.step().
#pragma once

#include <functional>
#include <string>

namespace ballpit {

class Scheduler;
class World;

class FixedStepLoop {
 public:
  FixedStepLoop(World& world, Scheduler& scheduler);

  // One step: validates dt, runs every scheduled system once per pass (one pass unless motion
  // is too fast for the margin cap), counts the step, and records its passes in world.passes.
  void step();
  // Advances by real elapsed time; returns the number of steps taken.
  int advance(double real_seconds);
  // Fraction of a step between the last step and now, in [0, 1).
  float alpha() const;

  int max_catch_up = 4;
  // Told, the first time a step needs more passes than it may take, what happened and what dt
  // holds it (short_of_passes_warning). Prints "ballpit: warning: ..." on stderr by default.
  std::function<void(const std::string&)> warn;

 private:
  void run_pass(float length, bool split);

  World& world_;
  Scheduler& scheduler_;
  double accumulator_ = 0.0;
};

}  // namespace ballpit
