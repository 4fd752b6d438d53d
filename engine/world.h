// The simulation state: entity registry, component tables, shared resources (grid, contacts)
// and the scene's settings. Systems read and write it through the columns they declare.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/character.h"
#include "engine/collider_table.h"
#include "engine/contact_set.h"
#include "engine/entity.h"
#include "engine/settings.h"
#include "engine/spatial_grid.h"
#include "engine/sphere_table.h"
#include "engine/step_passes.h"

namespace ballpit {

// The longest substep (dt / substeps, unit: s) at which the pour settles with its deepest overlap
// within 1% of r: 0.26% at 1/240 s, 2.9% at 1/180 s, 14% at 1/120 s (10k spheres,
// profiling/reports/speed_error.md).
inline constexpr float kLongestAccurateSubstep = 1.0f / 240.0f;

// Substeps that a Solve sweep beyond the first stands in for, and the most sweeps that do: the 10k
// pour at 1/60 s settles within 1% of r at 3 substeps of 2 sweeps (0.02%) and 2 of 3 (0.45%), not
// at 2 of 2 (2.0%) nor 1 of 8 (1.8%) (profiling/reports/solve_sweeps/speed_error.md and runs of
// `ballpit run --spheres 10000 --substeps S --set solver.solve_sweeps=N`).
inline constexpr int kSubstepsPerExtraSweep = 1;
inline constexpr int kMostSweepsThatReplaceSubsteps = 3;

// The fewest substeps that keep a settled pile within 1% of r: dt / substeps within
// kLongestAccurateSubstep, less what Solve sweeps beyond the first make up for.
int accurate_substeps(float dt, int solve_sweeps = 1);

// The longest step (unit: s) past which a step costs more per simulated second than shorter
// ones, whatever its substeps: a ball's speculative margin grows with dt^2 and outgrows the
// grid's cells, so every ball searches a wider box. A 2,000-ball pour with substeps of 1/240 s
// cost 66 ms per simulated second at dt = 1/60 s, 110 at 1/30, 161 at 1/20 and 2,490 at 1/10.
inline constexpr float kLongestCheapStep = 1.0f / 30.0f;

// The most velocity gravity may add in one substep, as a fraction of the push-out cap
// (SolverSettings::push_out_speed), for a resting pile under heavy gravity to hold. A pile's lower
// layers are pushed back up by push-out, which the cap limits. The 1,000-ball pour at gravity
// 1e4 m/s^2 (about 5 passes a step) sank into itself, pairs 1.99 r deep, at 2.1 (4 substeps,
// 4 m/s); at 0.049 (4 substeps, 170 m/s) it was 1.19 r deep, at 0.042 (8, 100 m/s) 0.73 r, and at
// 0.021 (16, 100 m/s) 0.114 r. Measured only there, so the warning speaks only where gravity is
// over kHeavyGravity; at Earth's, a long substep has its own warning (StepWarnings::substep).
inline constexpr float kMostGravityPerSubstepOfPushOut = 0.025f;
inline constexpr float kHeavyGravity = 98.1f;  // ten times Earth's (unit: m/s^2)

class World {
 public:
  World();

  // Adds a sphere after validating it (see SphereDesc); throws ballpit::Error naming the entity.
  Entity add_sphere(const SphereDesc& d);
  void remove_sphere(Entity e);

  // Gravity may change at any time (the app ties it to the camera); it wakes every sleeper,
  // since a resting pile is only at rest for the gravity it settled under.
  void set_gravity(const Vec3& g);
  const Vec3& gravity() const { return gravity_; }

  // Validates and sets the fixed step (unit: s); throws ballpit::Error if not finite and > 0.
  void set_step(float dt);
  float step() const { return dt_; }

  // Sets the solver's substeps between steps (the substep controller, the app's slider, a run
  // resumed from a snapshot at other substeps); throws ballpit::Error outside [1, 64]. The
  // warm-start cache holds impulses of one substep, so they are scaled to the new substep's
  // length: left as they were, a cache made at 3 substeps warm-started 32 with ten times the
  // load, and the pit-character case at --tolerance 0.01 flung a ball at 113 m/s.
  void set_substeps(int substeps);
  // Sets the Solve sweeps per substep between steps (the app's slider); throws ballpit::Error,
  // changing nothing, outside [1, kMaxSolveSweeps]. The warm-start cache stays as it is: its
  // impulses are a substep's, however many sweeps made them.
  void set_solve_sweeps(int sweeps);

  // What a user should know of dt and substeps (engine/world.cpp words it). Both are allowed
  // (the speed-error study runs long substeps): a long substep softens every contact, so a pile
  // sinks into itself, and a long step costs more than the short ones it replaces.
  struct StepWarnings {
    std::string substep;  // dt / substeps is longer than kLongestAccurateSubstep, and what would do
    std::string step;     // dt is longer than kLongestCheapStep
    std::string passes;   // even a resting ball needs more passes than a step may take (step_passes.h)
    std::string gravity;  // a substep's gravity outruns the push-out cap: a resting pile sinks into itself
  };
  StepWarnings step_warnings() const;

  // Angular state exists only in scenes that can spin spheres (any friction).
  void enable_angular(bool enabled) { spheres.set_angular(enabled); }

  std::uint16_t add_material(const Material& m);
  // Throws ballpit::Error if the settings are out of range, naming the field.
  void validate_settings() const;

  EntityRegistry entities;
  SphereTable spheres;
  ColliderTable colliders;
  CharacterTable characters;  // empty unless the scene has a character (systems/character_pipeline.h)
  std::vector<Material> materials;
  Pit pit;
  SolverSettings solver;
  SpatialGrid grid;
  ContactSet contacts;
  std::uint64_t step_count = 0;
  PassRecord passes;  // what the last step took (engine/step_passes.h); the fixed-step loop writes it

 private:
  Vec3 gravity_ = Vec3(0.0f, -9.81f, 0.0f);
  float dt_ = 1.0f / 60.0f;
};

}  // namespace ballpit
