// The cases of the speed-against-error study (issue 5), each with an exact or reference answer,
// and the solver settings it sweeps. A case builds its world, applies one SolverPoint, runs
// with only the physics step timed, and returns its cost, its error (the Pareto axis) and the
// figures behind the error, plus the state hash so the point can be reproduced exactly.
//
// Cost is the median step's wall time per simulated second (ms/s): it compares settings with
// different step sizes fairly, and the median resists a shared machine's interruptions. Error is per case:
//   bounce   max over the first 3 bounces of |apex / (H e^2k) - 1| (dropped from H = 1 m, e = 0.5)
//   cradle   momentum not where it should be after 1 s, / p0: (|p_last - p0| + sum |p_other|) / p0
//   stack    max(drift, overlap, floor overlap) of a 50-sphere column after 20 s, / r
//   pour     max sphere-sphere penetration at the end of the 10 s pour, / r
//   gas      |KE(10,000 steps) / KE(0) - 1| of 2,000 elastic spheres in a closed box, no gravity
//   crowd    speed the solver made (top ball speed - g t, m/s), worst step of 5 s, worst of 5
//            random crowds of 1,000 spheres spawned in a tenth of the room they need
//   character  deepest overlap after a step (ball-ball, wall, joint collider) / r, worst step of
//            the pit-character path
// Every point also records max_step_penetration_r (and its mean over the steps), the worst overlap after any timed step as
// the substep controller measures it (systems/substep_control.h): what a tolerance point
// promises to bound, so tolerance and fixed points compare on it too.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/pour_scene.h"
#include "engine/settings.h"

namespace ballpit {
class World;
}

namespace ballpit::profiling {

// One point of the sweep: the solver settings (engine/settings.h SolverSettings) and the step.
// Every field starts at the engine's default, so the "default" point is whatever the engine
// ships, and the other points are labelled by what they change.
struct SolverPoint {
  std::string label = "default";
  int substeps = SolverSettings{}.substeps;
  int solve_sweeps = SolverSettings{}.solve_sweeps;  // Gauss-Seidel sweeps of the Solve pass per substep
  float push_out_rate = SolverSettings{}.push_out_rate;  // fraction of overlap per substep
  float push_out_speed = SolverSettings{}.push_out_speed;  // (unit: m/s)
  float restitution_threshold = SolverSettings{}.restitution_threshold;  // (unit: m/s)
  float dt = PourScene{}.dt;  // (unit: s)
  // > 0: tolerance mode (`ballpit run --tolerance`): the substep controller picks the substeps
  // every step, starting from `substeps`, to keep the overlap after a step under this x r.
  double tolerance_r = 0.0;

  // Sets world.solver's fields and the step; the scene's other settings stay.
  void apply(World& world) const;
  nlohmann::ordered_json to_json() const;
};

// Tolerances of the tolerance-mode points (fractions of r), loosest first.
inline constexpr double kTolerancePoints[] = {0.01, 0.003, 0.001};

// The engine's defaults, then one-at-a-time variations around them (substeps, push-out rate,
// push-out speed cap, step size at fixed and at scaled substeps, restitution threshold, Solve
// sweeps, alone and traded against substeps), then tolerance mode at each of kTolerancePoints
// (from the default settings).
std::vector<SolverPoint> sweep_points();
// The few points run on the expensive big pour: the default, half and twice its substeps, the
// previous default, the loosest tolerance, and fewer substeps of more Solve sweeps.
std::vector<SolverPoint> big_pour_points();

// Results (errors, state hashes) are the same for any thread count: the engine is deterministic.
// Costs are measured on 1 thread by default: the ranking of settings is what the study needs, and
// a 1-thread run is the one a shared machine disturbs least (a 2-thread run loses whole time
// slices at every barrier whenever another process holds the other core).
struct CaseOptions {
  int threads = 1;        // gas, crowd, pour, character
  int small_threads = 1;  // bounce, cradle, stack: 1 to 50 spheres
  std::size_t pour_spheres = 10000;
  std::size_t character_spheres = 5000;
};

// Each returns one JSON object: case, point settings, spheres, steps, sim_s, ms_per_step,
// cost_ms_per_sim_s, max_step_penetration_r, error, error_metric, the case's own figures,
// state_hash; tolerance points add substeps_mean, substeps_min, substeps_max and
// steps_over_tolerance.
nlohmann::ordered_json run_bounce(const SolverPoint& p, const CaseOptions& o);
nlohmann::ordered_json run_cradle(const SolverPoint& p, const CaseOptions& o);
nlohmann::ordered_json run_stack(const SolverPoint& p, const CaseOptions& o);
nlohmann::ordered_json run_pour(const SolverPoint& p, const CaseOptions& o);
nlohmann::ordered_json run_gas(const SolverPoint& p, const CaseOptions& o);
nlohmann::ordered_json run_crowd(const SolverPoint& p, const CaseOptions& o);
// pit-character (shared/SCENES.md) at CaseOptions::character_spheres: settled untimed, then the
// 10 s scripted path timed.
nlohmann::ordered_json run_character(const SolverPoint& p, const CaseOptions& o);

}  // namespace ballpit::profiling
