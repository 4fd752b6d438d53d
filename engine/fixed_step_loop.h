// The fixed-step loop: physics always advances by the world's dt, however long a frame took.
// Real time accumulates; whole steps are taken from it, at most max_catch_up per call, so a
// long hitch (a debugger pause, a slow frame) drops time instead of spiralling into ever more
// catch-up steps. What is left over is the interpolation fraction for rendering.
#pragma once

namespace ballpit {

class Scheduler;
class World;

class FixedStepLoop {
 public:
  FixedStepLoop(World& world, Scheduler& scheduler) : world_(world), scheduler_(scheduler) {}

  // One step: validates dt, runs every scheduled system once, counts the step.
  void step();
  // Advances by real elapsed time; returns the number of steps taken.
  int advance(double real_seconds);
  // Fraction of a step between the last step and now, in [0, 1).
  float alpha() const;

  int max_catch_up = 4;

 private:
  World& world_;
  Scheduler& scheduler_;
  double accumulator_ = 0.0;
};

}  // namespace ballpit
