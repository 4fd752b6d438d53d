#include "fuzz/step_world.h"

#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/nan_guard.h"
#include "systems/physics_pipeline.h"

namespace ballpit::fuzz {

void step_small_world(World& world, int steps) {
  if (world.spheres.size() > kMaxSteppedSpheres) return;
  world.validate_settings();  // what the headless run checks before it schedules the systems
  Scheduler scheduler(1);
  add_character_systems(scheduler, world);  // none without a character
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);
  NanGuard guard(world);
  for (int s = 0; s < steps; ++s) guard.step(loop, world, scheduler);
}

}  // namespace ballpit::fuzz
