// Substep control: accuracy as an input (`ballpit run --tolerance P`). After each step it
// measures the deepest overlap left by the step and picks the solver's substeps for the next
// one, so the measured overlap stays under P (a fraction of the ball radius) at the fewest
// substeps it can find.
//
// Reads: positions, radii, contacts, colliders. Writes: world.solver.substeps (a setting, not
// a column: only the solver reads it, and it runs before this system in the step, because it
// writes the positions and contacts this system reads).
//
// Decisions:
// - The measure is the step's own contact list (sphere pairs, pit planes, joint colliders) at
//   the positions the step ended with: O(contacts), parallel over slabs, and a max, so it is
//   exact in any order and the same for any thread count (the substeps chosen, and so the state
//   hash, are too). It does not look for overlaps the narrowphase did not list: the runner's
//   end-of-run metrics (engine/metrics.h, a search of their own) check that independently.
// - Raise fast, lower slowly. Over P the substeps grow at once in proportion to the overshoot
//   (at least 1.5x); near P (above kNearFraction x P) by one. Lowering needs calm_steps steps
//   in a row under kNearFraction x P, and then goes down only as far as the window's worst
//   overlap, scaled up as if it went as 1/substeps^2, stays under kLowerFraction x P: at most a
//   quarter fewer at once. A lowering followed by a raise within the calm period doubles the
//   calm period (up to kMaxCalmSteps): the controller stops probing a level it has just seen
//   fail, so it does not oscillate across a stability edge (a substep count below which a
//   pile's overlap grows step after step instead of shrinking).
// - Bounds [1, 32] by default: 32 is four times the default substeps, a ceiling on the cost; a
//   P that 32 substeps cannot hold is reported (the runner's steps_over_tolerance), not chased.
#pragma once

#include <cstdint>

#include "engine/system.h"

namespace ballpit {

class World;

// Deepest overlap among world.contacts at the current positions, / the ball's radius (the
// smaller one for a pair): sphere pairs, pit planes where they apply, and joint colliders at
// their end-of-step pose. 0 if nothing overlaps.
double contact_penetration_r(const World& world);

struct SubstepControlSettings {
  double tolerance_r = 0.01;  // largest overlap allowed after a step, / r (0 < P <= 1)
  int min_substeps = 1;
  int max_substeps = 32;
  int calm_steps = 10;        // steps under P (a sixth of a second at 1/60 s) before lowering
};

// The decision alone (no world): given the substeps the last step used and the overlap it left,
// the substeps for the next step. Deterministic: integer state and comparisons of the input.
class SubstepController {
 public:
  static constexpr double kNearFraction = 0.7;   // above this x P: one more substep
  static constexpr double kLowerFraction = 0.5;  // predicted overlap after lowering stays under this x P
  static constexpr double kLowerStep = 0.75;     // lower to no fewer than this x the substeps at once
  static constexpr int kMaxCalmSteps = 600;      // 10 s at 1/60 s

  // Throws ballpit::Error if the tolerance or the bounds are out of range, naming the field.
  explicit SubstepController(const SubstepControlSettings& settings);
  int next(int substeps, double overlap_r);
  const SubstepControlSettings& settings() const { return settings_; }

 private:
  SubstepControlSettings settings_;
  int calm_needed_;
  int calm_ = 0;                 // steps in a row under kNearFraction x P
  double window_max_ = 0.0;      // worst overlap of those steps
  int since_lowered_ = -1;       // steps since the last lowering (-1: none pending)
};

// What the controller did over the steps it saw since the last reset (the report's fields).
struct SubstepControlStats {
  std::uint64_t steps = 0;
  std::uint64_t substeps_sum = 0;  // substeps used, summed over the steps
  int substeps_min = 0;
  int substeps_max = 0;
  double max_overlap_r = 0.0;      // worst measured overlap after a step, / r
  std::uint64_t steps_over = 0;    // steps whose measured overlap exceeded the tolerance

  double substeps_mean() const { return steps ? static_cast<double>(substeps_sum) / static_cast<double>(steps) : 0.0; }
};

class SubstepControlSystem : public System {
 public:
  explicit SubstepControlSystem(const SubstepControlSettings& settings) : controller_(settings) {}
  std::string_view name() const override { return "substep_control"; }
  Access access() const override;
  void run(World& world) override;
  bool data_parallel() const override { return true; }

  const SubstepControlStats& stats() const { return stats_; }
  // Forgets the statistics (not the controller's state): the runner calls it when the timed
  // part of a run starts, e.g. after the pit-character scene's untimed settling.
  void reset_stats() { stats_ = {}; }
  double tolerance_r() const { return controller_.settings().tolerance_r; }

 private:
  SubstepController controller_;
  SubstepControlStats stats_;
};

}  // namespace ballpit
