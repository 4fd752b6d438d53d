#include "engine/fixed_step_loop.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "engine/scheduler.h"
#include "engine/step_passes.h"
#include "engine/world.h"

namespace ballpit {

FixedStepLoop::FixedStepLoop(World& world, Scheduler& scheduler)
    : warn([](const std::string& text) { std::fprintf(stderr, "ballpit: warning: %s\n", text.c_str()); }),
      world_(world),
      scheduler_(scheduler) {}

void FixedStepLoop::run_pass(float length, bool split) {
  // A step of one pass at dt after another such step is what it always was: the cache is left
  // alone, as it always was when dt changed between steps.
  PassRecord& last = world_.passes;
  if ((split || last.last_split) && last.last_length > 0.0f && length != last.last_length)
    scale_warm_start(world_, length / last.last_length);
  last.last_length = length;
  last.last_split = split;
  world_.set_step(length);
  scheduler_.run_frame(world_);
}

void FixedStepLoop::step() {
  world_.set_step(world_.step());  // revalidates: a caller may have poked the settings
  const float dt = world_.step();
  PassRecord& record = world_.passes;
  record.passes = 0;
  record.needed = 0;
  record.longest = std::numeric_limits<float>::infinity();
  bool short_of_passes = false;
  float remaining = dt;
  // A world with joint colliders runs whole (engine/step_passes.h says why).
  const bool whole = world_.colliders.size() > 0;
  // The profiler's table is per step: a step's passes add up to one of its frames.
  struct StepTiming {
    Profiler& profiler;
    explicit StepTiming(Profiler& p) : profiler(p) { profiler.begin_step(); }
    ~StepTiming() { profiler.end_step(); }
  } timing(scheduler_.profiler());
  try {
    // Each pass is planned from the velocities the last one left: a ball that speeds up (or is
    // hit) shortens the passes after it, one that stops lengthens them.
    for (;;) {
      // Whole if it fits the cap (a calm step, as before passes existed); once split, every pass
      // is planned for the split margin (kSplitMarginFraction).
      float longest = whole ? std::numeric_limits<float>::infinity()
                            : record.passes == 0 ? longest_capped_pass(world_) : 0.0f;
      if (!(longest >= remaining)) longest = longest_capped_pass(world_, kSplitMarginFraction);
      const int wanted = passes_needed(remaining, longest);
      const int budget = kMostPassesPerStep - record.passes;
      record.needed = static_cast<int>(std::min<long long>(std::max<long long>(record.needed, 0LL + record.passes + wanted),
                                                           std::numeric_limits<int>::max()));
      record.longest = std::min(record.longest, longest);
      const int passes = std::min(wanted, budget);
      short_of_passes |= wanted > budget;
      // The last pass takes what is left, so the passes add up to dt exactly.
      const float length = passes == 1 ? remaining : remaining / static_cast<float>(passes);
      run_pass(length, record.passes > 0 || passes > 1);
      ++record.passes;
      remaining -= length;
      if (passes == 1) break;
    }
  } catch (...) {
    world_.set_step(dt);
    throw;
  }
  world_.set_step(dt);
  ++world_.step_count;
  if (short_of_passes && record.steps_short++ == 0 && warn) warn(short_of_passes_warning(world_, record));
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
