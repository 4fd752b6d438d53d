// Sleeping: a pile of spheres (spheres joined by contacts that carry load) that has stayed
// slower than sleep_speed for sleep_time sleeps as one: its spheres stop integrating, act as
// fixed bodies for awake spheres, and their pairs with each other are no longer generated or
// solved (the warm-start cache keeps those pairs' impulses, systems/solver.cpp). The pile wakes
// as one when a member moves, when an awake sphere or a joint collider touches a member faster
// than wake_speed, or when gravity changes (World::set_gravity). A lone sphere is a pile of one.
// Reads: velocities, radii, contacts (and the cache), colliders, rows. Writes: sleep state,
// velocities.
// Decision: sleep is per pile, not per sphere. A sphere asleep alone inside a pile is a fixed
// body there: it stops passing on the weight it carries, and its neighbours are warm-started
// with loads it no longer shares. Per-sphere sleep kept a settled 10k pour boiling for good
// (systems/sleeping.cpp). The cost: a pile with one moving ball stays awake whole.
#pragma once

#include "engine/system.h"

namespace ballpit {

class World;

// Wakes sleepers approached fast (from this step's contacts, found by the narrowphase).
void wake_approached(World& world);
// Applies the solver's wake requests, then counts still time and puts still spheres to sleep.
void update_sleep(World& world);

class WakeSystem : public System {
 public:
  std::string_view name() const override { return "wake"; }
  Access access() const override;
  void run(World& world) override { wake_approached(world); }
};

class SleepSystem : public System {
 public:
  std::string_view name() const override { return "sleeping"; }
  Access access() const override;
  void run(World& world) override { update_sleep(world); }
};

}  // namespace ballpit
