// Sleeping: a sphere that stays slower than sleep_speed for sleep_time sleeps: it stops
// integrating, acts as a fixed body for awake spheres, and its pairs with other sleepers are
// no longer generated or solved. A sleeper wakes when an awake sphere or a joint collider
// touches it faster than wake_speed, or when gravity changes (World::set_gravity).
// Reads: velocities, radii, contacts, colliders, rows. Writes: sleep state, velocities.
// Decision: sleep is per sphere, not per island. A ball pit settles into one big island that
// a single moving ball would keep awake; per-sphere sleep lets the quiet part of it rest.
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
