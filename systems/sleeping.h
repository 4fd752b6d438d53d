// Sleeping: a pile of spheres (spheres joined by contacts that carry load) that has stayed
// slower than sleep_speed for sleep_time sleeps as one: its spheres stop integrating, act as
// fixed bodies for awake spheres, and their pairs with each other are no longer generated or
// solved (the warm-start cache keeps those pairs' impulses, systems/solver.cpp). The pile wakes
// as one when a member moves, when an awake sphere or a joint collider touches a member faster
// than wake_speed, or when gravity changes (World::set_gravity). A lone sphere is a pile of one.
// Reads: velocities, radii, contacts (and the cache), colliders, rows; when a pile wakes, what
// the narrowphase reads. Writes: sleep state, velocities; contacts when a pile wakes.
// Decision: sleep is per pile, not per sphere. A sphere asleep alone inside a pile is a fixed
// body there: it stops passing on the weight it carries, and its neighbours are warm-started
// with loads it no longer shares. Per-sphere sleep kept a settled 10k pour boiling for good
// (systems/sleeping.cpp). The cost: a pile with one moving ball stays awake whole.
#pragma once

#include "engine/system.h"
#include "systems/narrowphase.h"

namespace ballpit {

class World;

// Wakes sleepers approached fast (from this step's contacts, found by the narrowphase), and
// the piles of those and of sleepers' neighbours that moved. Returns whether any sleeper woke.
bool wake_approached(World& world);
// Applies the solver's wake requests, then counts still time and puts still spheres to sleep.
void update_sleep(World& world);

// Runs after the narrowphase, which lists no pair of two sleepers: when it wakes a pile, it
// finds the step's contacts again, or the pile would be solved for this step with no contact
// among its balls and fall freely for it (g dt: 0.16 m/s, and overlaps of 0.08 r three steps
// later in a woken pile of 1,000). Steps that wake nothing cost no second search.
class WakeSystem : public System {
 public:
  std::string_view name() const override { return "wake"; }
  Access access() const override;
  void run(World& world) override;
  bool data_parallel() const override { return true; }

 private:
  NarrowphaseScratch scratch_;  // for the second search
};

class SleepSystem : public System {
 public:
  std::string_view name() const override { return "sleeping"; }
  Access access() const override;
  void run(World& world) override { update_sleep(world); }
  bool data_parallel() const override { return true; }
};

}  // namespace ballpit
