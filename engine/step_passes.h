// Passes of a step: when spheres move too fast (or gravity pulls too hard, or dt is too long)
// for a speculative margin within the cap (kMostMarginFraction r, engine/speculative_margin.h),
// the fixed-step loop runs the step as k passes of every system at dt / k, each re-planned from
// the velocities the last one left, so that every pass's margins fit under the cap. A step whose
// margins already fit is one pass at dt, exactly as before passes existed.
// Reads: sphere velocities, radii, sleep; gravity. Writes: nothing (planning), the warm-start
// cache's scale (scale_warm_start).
// Decision: whole passes rather than swept tests for fast spheres. A pass costs what a calm step
// costs (each sphere lists at most its near neighbours, engine/speculative_margin.h), the
// solver, joint colliders and planes need no new kind of contact, and the result is the same for
// any thread count because the plan is a max over spheres, which does not depend on order.
// Not yet under joint colliders: a world with any runs whole steps with uncapped margins, as
// before. Split, a capsule posed once a step (by a test, or a user) stands still through the
// passes and jumps at the next step, or, moved along its velocity between passes, crushed a pile
// into the floor and flung a ball at 36 m/s where one strike allows 17.8
// (tests/test_character_pushing.cpp); how a kinematic collider should move through passes is
// left open.
#pragma once

#include <cstdint>
#include <string>

#include "engine/speculative_margin.h"

namespace ballpit {

class World;

// The margin a split step's passes are planned for, as a fraction of the radius. A step that
// fits the cap (kMostMarginFraction) runs whole; one that does not is split finely enough that
// every margin is within this: a sphere then lists partners within (2 + 2 x 1) r = 4 r, at most
// 0.74 x 4^3 = 47 (the densest packing). Planned to the cap instead, the heavy scene's resting
// pile listed about 90 partners a sphere (margins of 2.5 r from g h^2 / 4 alone) and its solver
// took 12-26 ms a pass for 1,000 balls.
inline constexpr float kSplitMarginFraction = 1.0f;

// The most passes a step may take, which bounds a step's cost at that many calm passes. At
// dt = 1/60 s and r = 0.04 m, 100 m/s needs 43; the heavy scene's balls, falling at up to 155
// m/s, 66; a 1e-4 m ball falling at 0.44 m/s (1 cm) 75. Past that a shorter dt is the cheaper
// way, and the loop warns (FixedStepLoop) with the dt that holds it.
inline constexpr int kMostPassesPerStep = 128;

// The longest pass (unit: s) after which every awake sphere's pair margin, from its velocity
// now, is within margin_fraction x r: the largest h with v h + g h^2 / 4 <= (margin_fraction -
// kMinMarginFraction) r for every awake sphere (the fastest in radii per second and the
// smallest radius taken together, which can only shorten it). Infinite when nothing moves and
// nothing pulls; 0 for a non-finite velocity.
float longest_capped_pass(const World& world, float margin_fraction = kMostMarginFraction);

// The same for one sphere: the largest h with v h + g h^2 / 4 <= (margin_fraction -
// kMinMarginFraction) r, given v / r (unit: 1/s) and g / r (unit: 1/s^2). Infinite when both are
// 0, 0 when v / r is not finite.
double longest_pass_within(double speed_per_radius, double gravity_per_radius, float margin_fraction);

// Equal passes that `remaining` seconds need for passes within `longest` seconds, at least one;
// a count past any int a step could take comes back as INT32_MAX.
int passes_needed(float remaining, float longest);

// Scales the warm-start cache's impulses by `factor`: they are impulses of one substep, so a
// pass of another length must start from them scaled to its own (as World::set_substeps does).
void scale_warm_start(World& world, float factor);

// What the last step took (World::passes).
struct PassRecord {
  int passes = 1;      // passes taken
  int needed = 1;      // passes the margins needed (more than taken: the cap did not hold)
  float longest = 0;   // the shortest longest_capped_pass of its passes (unit: s)
  std::uint64_t steps_short = 0;  // steps so far that needed more passes than they could take
  // The last pass's length (unit: s; 0 before the first) and whether its step was split: the
  // warm-start cache holds impulses of one substep of that pass, which the next pass scales to
  // its own length. World state, so that a snapshot resumes as the run it was taken from.
  float last_length = 0.0f;
  bool last_split = false;
};

// The warning for a step that needed more passes than kMostPassesPerStep: what happened, why,
// and the dt that holds it.
std::string short_of_passes_warning(const World& world, const PassRecord& record);

}  // namespace ballpit
