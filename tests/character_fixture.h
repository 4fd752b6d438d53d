// Shared by the character suites: the two models of Debian's assimp-testmodels (imported once
// per test program), and a world with a character and its systems to step.
#pragma once

#include <memory>

#include "engine/fixed_step_loop.h"
#include "engine/model_import.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/physics_pipeline.h"

namespace ballpit::test {

inline constexpr const char* kEpilepticPath = "/usr/share/assimp/models/X/BCN_Epileptic.X";

inline std::shared_ptr<const Model> wuson() {
  static const std::shared_ptr<const Model> model = import_model(kWusonModelPath);
  return model;
}
inline std::shared_ptr<const Model> epileptic() {
  static const std::shared_ptr<const Model> model = import_model(kEpilepticPath);
  return model;
}

// A character in an empty pit (no balls unless a test adds them), stepped at 60 Hz.
struct CharacterSim {
  World world;
  Entity character;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<FixedStepLoop> loop;

  explicit CharacterSim(const CharacterDesc& desc = CharacterDesc::wuson(), float pit_half_width = 50.0f) {
    world.pit.half_width = pit_half_width;
    character = add_character(world, wuson(), desc);
  }
  // Schedules the character systems, then the physics ones when there are balls.
  void start(int threads = 1) {
    scheduler = std::make_unique<Scheduler>(threads);
    add_character_systems(*scheduler, world);
    if (world.spheres.size() > 0) add_physics_systems(*scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, *scheduler);
  }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) loop->step();
  }
  const CharacterSetup& setup() const { return world.characters.setup(0); }
  const CharacterMotion& motion() const { return world.characters.motion(0); }
  const CharacterPose& pose() const { return world.characters.pose(0); }
  CharacterMotion& mut_motion() { return world.characters.mut_motion(0); }
};

}  // namespace ballpit::test
