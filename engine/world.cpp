#include "engine/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "engine/error.h"
#include "engine/speculative_margin.h"

namespace ballpit {

World::World() { materials.push_back(Material{}); }

Entity World::add_sphere(const SphereDesc& d) {
  Entity e = entities.create();
  try {
    if (d.material >= materials.size()) {
      throw Error("sphere " + to_string(e) + ": material " + std::to_string(d.material) +
                  " does not exist (the world has " + std::to_string(materials.size()) + ")");
    }
    spheres.add(e, d);
  } catch (...) {
    entities.destroy(e);
    throw;
  }
  return e;
}

void World::remove_sphere(Entity e) {
  // The table moves its last row into the removed one; the rows the last store marked asleep
  // move alike, so that they keep naming the spheres in those rows (the solver reads them to
  // tell which spheres it kept: systems/solver.cpp, keep_sleepers). A row past them was added
  // since, awake then.
  const std::uint32_t row = spheres.row(e), last = static_cast<std::uint32_t>(spheres.size() - 1);
  std::vector<std::uint8_t>& slept = contacts.row_slept;
  if (row < slept.size()) slept[row] = last < slept.size() ? slept[last] : std::uint8_t{0};
  if (last < slept.size()) slept[last] = 0;
  spheres.remove(e);
  contacts.kept.forget(e.index);
  entities.destroy(e);
}

void World::set_gravity(const Vec3& g) {
  if (!all_finite(g)) throw Error("gravity must be finite");
  if (g == gravity_) return;
  gravity_ = g;
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  std::fill(asleep.begin(), asleep.end(), std::uint8_t{0});
  std::fill(still.begin(), still.end(), 0.0f);
}

void World::set_step(float dt) {
  if (!std::isfinite(dt) || !(dt > 0.0f)) {
    throw Error("step dt must be a finite number > 0 s, got " + std::to_string(dt));
  }
  dt_ = dt;
}

void World::set_substeps(int substeps) {
  if (substeps < 1 || substeps > 64) throw Error("solver.substeps must be in [1, 64], got " + std::to_string(substeps));
  if (substeps == solver.substeps) return;
  const float scale = static_cast<float>(solver.substeps) / static_cast<float>(substeps);
  contacts.scale_impulses(scale);
  solver.substeps = substeps;
}

namespace {

void check_solve_sweeps(int sweeps) {
  if (sweeps < 1 || sweeps > kMaxSolveSweeps)
    throw Error("solver.solve_sweeps must be in [1, " + std::to_string(kMaxSolveSweeps) + "], got " + std::to_string(sweeps));
}

}  // namespace

void World::set_solve_sweeps(int sweeps) {
  check_solve_sweeps(sweeps);
  solver.solve_sweeps = sweeps;
}

int accurate_substeps(float dt, int solve_sweeps) {
  // The slack keeps dt = 1/60 s at 4 substeps, which float rounding puts a hair past 4.
  // Capped well inside int: any dt a scene accepts gives a count.
  const double substeps = std::ceil(static_cast<double>(dt) / kLongestAccurateSubstep * (1.0 - 1e-5));
  const int replaced = kSubstepsPerExtraSweep * (std::clamp(solve_sweeps, 1, kMostSweepsThatReplaceSubsteps) - 1);
  return std::max(1, static_cast<int>(std::min(substeps, 1e9)) - replaced);
}

World::StepWarnings World::step_warnings() const {
  StepWarnings warnings;
  char text[400];
  auto say = [&](int written) {  // what snprintf wrote into text
    return std::string(text, static_cast<std::size_t>(std::clamp(written, 0, static_cast<int>(sizeof text) - 1)));
  };
  if (const int needed = accurate_substeps(dt_, solver.solve_sweeps); solver.substeps < needed) {
    const int sweeps = solver.solve_sweeps;
    std::string warning = say(std::snprintf(text, sizeof text, "a substep of %.3g ms (dt %.4g s over %d substep%s",
                                            1e3 * dt_ / solver.substeps, static_cast<double>(dt_), solver.substeps,
                                            solver.substeps == 1 ? "" : "s"));
    if (sweeps == 1)
      warning += ") is longer than 1/240 s: a settled pile overlaps deeper than 1% of r (the 10k pour: 2.9% at 1/180 s, "
                 "14% at 1/120 s; profiling/reports/speed_error.md). ";
    else
      warning += say(std::snprintf(text, sizeof text,
          " of %d Solve sweeps) is longer than 1/240 s by more substeps than the sweeps beyond the first make up for "
          "(one each, at most %d): a settled pile overlaps deeper than 1%% of r (the 10k pour: 2.0%% at 2 substeps of "
          "2 sweeps, 1.8%% at 1 of 8; profiling/reports/solve_sweeps/speed_error.md). ",
          sweeps, kSubstepsPerExtraSweep * (kMostSweepsThatReplaceSubsteps - 1)));
    if (needed <= 64)
      warning += std::to_string(needed) +
                 " substeps keep it within (solver.substeps, --substeps), or --tolerance chooses them step by step.";
    else
      warning += say(std::snprintf(text, sizeof text, "No substep count up to 64 does: a dt of %.4g s or less is needed.",
                                   64.0 * kLongestAccurateSubstep));
    warnings.substep = std::move(warning);
  }
  if (dt_ > kLongestCheapStep * (1.0f + 1e-5f))
    warnings.step = say(std::snprintf(text, sizeof text,
        "a step of dt %.4g s is longer than 1/30 s: speculative margins grow with dt^2, so every ball searches a "
        "wider box, up to the margin cap (2.5 r), past which the step runs as several passes (before the cap, a "
        "2,000-ball pour cost 66 ms per simulated second at 1/60 s, 161 at 1/20 s, 2,490 at 1/10 s). Shorter steps "
        "are cheaper as well as more accurate.",
        static_cast<double>(dt_)));
  // A resting ball's margin still grows with g h^2 / 4 over a pass of h: the smallest ball at rest
  // bounds every pass from above, whatever else moves.
  float smallest = std::numeric_limits<float>::infinity();
  for (float r : spheres.radius()) smallest = std::min(smallest, r);
  const double g = gravity_.norm();
  if (g > 0.0 && std::isfinite(smallest)) {
    const double resting_pass = longest_pass_within(0.0, g / smallest, kSplitMarginFraction);
    // The substep a resting pile gets: dt in as many passes as resting balls need, if split.
    const double longest_whole = longest_pass_within(0.0, g / smallest, kMostMarginFraction);
    const double pile_passes = dt_ <= longest_whole ? 1.0 : std::min<double>(kMostPassesPerStep, std::ceil(dt_ / resting_pass));
    const double substep = dt_ / pile_passes / solver.substeps;
    const double gained = g * substep;  // unit: m/s
    if (g > kHeavyGravity && gained > kMostGravityPerSubstepOfPushOut * solver.push_out_speed) {
      // The measured remedy: a 100 m/s cap, and substeps enough for it.
      const double held_cap = std::max(100.0, static_cast<double>(solver.push_out_speed));
      const double substeps_needed = std::ceil(solver.substeps * gained / (kMostGravityPerSubstepOfPushOut * held_cap));
      std::string text_gravity = say(std::snprintf(text, sizeof text,
          "gravity of %.3g m/s^2 adds %.3g m/s in a substep of %.3g ms, more than %.1f%% of the push-out cap "
          "(solver.push_out_speed %.3g m/s): a resting pile cannot be pushed back up as fast as it sinks, and sinks "
          "into itself (the 1,000-ball pour at 1e4 m/s^2: pairs 1.99 r deep at 4 m/s and 4 substeps, 0.114 r at 100 "
          "m/s and 16). ",
          g, gained, 1e3 * substep, 100.0 * kMostGravityPerSubstepOfPushOut, static_cast<double>(solver.push_out_speed)));
      if (substeps_needed <= 64)
        text_gravity += say(std::snprintf(text, sizeof text, "solver.push_out_speed %.3g m/s with %d substeps holds it.",
                                          held_cap, static_cast<int>(substeps_needed)));
      else
        text_gravity += say(std::snprintf(text, sizeof text,
            "No substep count up to 64 holds it at a push-out cap of %.3g m/s: a shorter dt does.", held_cap));
      warnings.gravity = std::move(text_gravity);
    }
    if (dt_ > kMostPassesPerStep * resting_pass)
      warnings.passes = say(std::snprintf(text, sizeof text,
          "gravity of %.3g m/s^2 on a ball of r = %.3g m needs passes of at most %.3g s to keep speculative margins "
          "within %.1f r, and a step of dt %.4g s may take at most %d: balls can end inside each other. A dt of %.3g s "
          "or less holds it (--set dt=...).",
          g, static_cast<double>(smallest), resting_pass, static_cast<double>(kSplitMarginFraction),
          static_cast<double>(dt_), kMostPassesPerStep, kMostPassesPerStep * resting_pass));
  }
  return warnings;
}

std::uint16_t World::add_material(const Material& m) {
  if (!(m.restitution >= 0.0f && m.restitution <= 1.0f))
    throw Error("material restitution must be in [0, 1], got " + std::to_string(m.restitution));
  if (!(m.friction >= 0.0f) || !std::isfinite(m.friction))
    throw Error("material friction must be a finite number >= 0, got " + std::to_string(m.friction));
  materials.push_back(m);
  return static_cast<std::uint16_t>(materials.size() - 1);
}

void World::validate_settings() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error(what);
  };
  const SolverSettings& s = solver;
  require(s.substeps >= 1 && s.substeps <= 64, "solver.substeps must be in [1, 64], got " + std::to_string(s.substeps));
  check_solve_sweeps(s.solve_sweeps);
  require(s.push_out_rate > 0 && s.push_out_rate <= 1, "solver.push_out_rate must be in (0, 1]");
  require(s.push_out_speed > 0 && std::isfinite(s.push_out_speed), "solver.push_out_speed must be > 0 m/s");
  require(s.restitution_threshold >= 0 && std::isfinite(s.restitution_threshold),
          "solver.restitution_threshold must be >= 0 m/s");
  require(s.linear_damping >= 0 && s.angular_damping >= 0, "solver damping must be >= 0 1/s");
  require(s.sleep_speed >= 0 && s.sleep_time > 0 && s.wake_speed >= 0, "solver sleep settings must be >= 0");
  require(pit.half_width > 0 && std::isfinite(pit.half_width), "pit.half_width must be > 0 m");
  require(pit.wall_height > 0 && std::isfinite(pit.wall_height), "pit.wall_height must be > 0 m");
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const Material& m = materials[i];
    require(m.restitution >= 0 && m.restitution <= 1, "materials[" + std::to_string(i) + "].restitution must be in [0, 1]");
    require(m.friction >= 0 && std::isfinite(m.friction), "materials[" + std::to_string(i) + "].friction must be >= 0");
  }
}

}  // namespace ballpit
