// Everything a scene sets that is not a per-sphere value: the pit, the materials, the solver.
// Defaults are the ones the speed-against-error study picked (profiling/reports/speed_error.md,
// "Why the default is the default", states the rule and checks it); each field says its unit
// and why its default is what it is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/math.h"

namespace ballpit {

struct Material {
  float restitution = 0.5f;  // coefficient of restitution, 0..1 (unitless)
  float friction = 0.5f;     // Coulomb coefficient (unitless)
};

// Pair values combine as Box2D does: restitution takes the bouncier surface, friction the
// geometric mean, so a frictionless surface is frictionless against anything.
Material combine(const Material& a, const Material& b);

// Axis-aligned pit: floor at y = 0, walls at x, z = +-half_width, up to wall_height. A closed
// pit also has a lid at wall_height (the tests' closed boxes).
struct Pit {
  float half_width = 1.0f;    // (unit: m)
  float wall_height = 20.0f;  // (unit: m)
  bool closed = false;
  Material material;

  // Plane i as n . x >= offset for points inside. Planes: floor, -x, +x, -z, +z, lid.
  static constexpr int kMaxPlanes = 6;
  // Inline, as plane_applies: the solver's pit guard and plane packing ask for every sphere, and
  // out of line the guard alone cost 1.06 ms a step at 100k spheres (now 0.4).
  int plane_count() const { return closed ? 6 : 5; }
  Vec3 plane_normal(int i) const {
    switch (i) {
      case 0: return Vec3(0, 1, 0);
      case 1: return Vec3(1, 0, 0);
      case 2: return Vec3(-1, 0, 0);
      case 3: return Vec3(0, 0, 1);
      case 4: return Vec3(0, 0, -1);
      default: return Vec3(0, -1, 0);
    }
  }
  float plane_offset(int i) const {
    switch (i) {
      case 0: return 0.0f;
      case 5: return -wall_height;
      default: return -half_width;
    }
  }
  // A wall stops a sphere only below its top edge; the floor and lid everywhere.
  bool plane_applies(int i, const Vec3& position) const { return i == 0 || i == 5 || position.y() < wall_height; }
  bool inside(const Vec3& position, float radius) const;
};

enum class NarrowphaseMode : std::uint8_t { Grid, Naive };

inline constexpr int kMaxSolveSweeps = 16;

struct SolverSettings {
  // Substeps per step. Each substep integrates, warm-starts, solves, moves and relaxes
  // (systems/solver.h). More substeps cost linearly and converge deep piles better. Four with a
  // push-out rate of 0.8 meet every bound of the study at 0.79x the cost of six at 0.4 (the
  // default until then) for 0.96x its error (profiling/reports/speed_error.md): the faster push
  // buys back what the two substeps lose.
  int substeps = 4;
  // Gauss-Seidel sweeps of the Solve pass per substep (1..kMaxSolveSweeps). A sweep costs about
  // what a substep's warm start and relax cost together, so fewer substeps of more sweeps cost
  // about as much (3 of 2 against the default: 0.90x on the 10k pour, 1 thread; the 100k pour's
  // settled step on 2 threads 22.06 against 21.53 ms, then 27.19 against 22.65 on a busier
  // machine). A sweep hands a push only a few spheres into a jam, so piles converge better on
  // more sweeps: 3 substeps of 2 left the 10k pour 7x less deep (0.00022 r) and the 100k pour
  // 5.8x, gave a spawned crowd a tenth of the speed, and the pit-character's worst pinch 0.43 r
  // instead of 0.71 (4 of 2: 0.20 r, at 1.11x). But the substeps are what time an impact: at 3,
  // a dropped ball bounces 1.5% off e^2 (0.65% at 4; the hard case's bound is 1%) and the
  // elastic gas drifts twice as far. So one sweep stays the default
  // (profiling/reports/solve_sweeps/speed_error.md, scripts/profile_solve_sweeps.sh).
  int solve_sweeps = 1;
  // Fraction of an overlap pushed out per substep, through split-impulse pseudo-velocity
  // (unitless, 0..1). Pseudo-velocity is forgotten after each move, so a fast rate costs no
  // energy. A fast rate once let a crowd squeeze a ball out of the pit and fling piled balls off
  // the floor; the pit guard and the plane-impact rule (systems/solver.cpp,
  // systems/contact_kernel.h) ended both. A 50-ball stack placed touching is within 0.04 r of
  // its place after 20 s at 4 substeps and 0.8; at 0.4 it is 0.38 r off, past the study's
  // quarter radius.
  float push_out_rate = 0.8f;
  // Cap on the speed at which overlapping spheres are pushed apart. Deep overlaps (spawned
  // inside each other) separate over several steps instead of jumping apart (unit: m/s).
  // Push-out is pseudo-velocity, so the cap bounds how fast overlap is removed, not how fast
  // spheres fly: a crowd spawned inside itself made 4.3 m/s of real speed at a 1 m/s cap
  // (its overlap lingered, and warm starts and impacts fed on it) and 0.3 m/s at 4 m/s, with
  // every other case equal (profiling/reports/speed_error.md).
  float push_out_speed = 4.0f;
  // Impacts slower than this are perfectly inelastic, so resting piles do not jitter
  // (unit: m/s). 0 gives every approach its restitution (elastic gas tests).
  float restitution_threshold = 0.25f;
  float linear_damping = 0.0f;   // (unit: 1/s)
  float angular_damping = 0.0f;  // (unit: 1/s)
  NarrowphaseMode narrowphase = NarrowphaseMode::Grid;
  // The solver keeps each sphere pair's contact frame (normal, gap) from one pass for the next
  // while the spheres have not moved (systems/contact_batch.h). false recomputes it in every pass: a
  // reference mode, as the naive narrowphase is, that must give bit for bit the same state.
  bool keep_pair_frames = true;

  bool sleeping = true;
  float sleep_speed = 0.02f;  // below this, and near where it was, a sphere counts as still (unit: m/s; systems/sleeping.h)
  float sleep_time = 0.5f;    // still for this long, it sleeps (unit: s)
  float wake_speed = 0.05f;   // a sphere faster than this keeps the sleep regions it may reach awake; twice this wakes them (unit: m/s; systems/sleep_regions.h)
};

}  // namespace ballpit
