// Sleeping, by region: the pit is cut into columns along gravity (systems/sleep_regions.h), and
// the spheres of a column that have stayed slower than sleep_speed, and within a tenth of their
// radius of where they were, for sleep_time fall asleep together from the floor up to a little
// under the lowest sphere of the column that has not, or that motion may reach, whatever the
// columns around them do. A sleeper stops integrating and is a fixed body for the awake spheres
// and limbs that meet it; its pairs with other sleepers, its floor and its walls are neither
// found nor solved, and the warm-start cache keeps their impulses (systems/solver.cpp), so it
// wakes carrying the load it carried.
// A column wakes from the lowest point a mover may reach up, before the step that could reach
// it, when a moving sphere (faster than kApproachWakeFactor x wake_speed) or a joint collider
// moving at all comes within a step's travel of it; after a step, from a region's width under a
// sleeper up, when the solver struck that sleeper harder than kStruckWakeFactor x wake_speed (a
// ball it held up moved away, or landed on it), or an awake sphere presses it past 2% r, or past
// 1% r after being still for sleep_time (a jam only the sleeper can free); and everywhere when
// gravity changes (World::set_gravity). Waking is by region, so it spreads only as far as
// motion does.
// Reads: positions, velocities, radii, colliders, gravity; the solver's wake requests.
// Writes: sleep state; velocities (zeroed when a sphere falls asleep).
// Decision: regions, not piles nor single spheres. A pile in a pit is the whole pit, so a pile
// that sleeps as one never sleeps while anything moves (issue 39: the 40,000 balls of the play
// scene cost the same with sleeping on). A sphere asleep alone inside an awake pile is a fixed
// body there that stops passing on the weight it carries, and a settled 10k pour slept and woke
// that way part by part for good. A column sleeps with the weight it carries inside it.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/system.h"

namespace ballpit {

class World;

// Wakes every sleeper that moving spheres or moving joint colliders may reach in the coming step,
// with the sleepers above it in its region. Returns the number of spheres it woke.
std::size_t wake_approached(World& world);
// Applies the solver's wake requests by region, counts still time, and puts each region whose
// spheres are all still, and that no motion may reach, to sleep.
void update_sleep(World& world);

// First in the step, before the grid: a region it wakes is searched and solved with the rest.
class WakeSystem : public System {
 public:
  std::string_view name() const override { return "wake"; }
  Access access() const override;
  void run(World& world) override { wake_approached(world); }
  bool data_parallel() const override { return true; }
};

class SleepSystem : public System {
 public:
  std::string_view name() const override { return "sleeping"; }
  Access access() const override;
  void run(World& world) override { update_sleep(world); }
  bool data_parallel() const override { return true; }
};

}  // namespace ballpit
