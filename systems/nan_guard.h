// The NaN guard: steps the world and checks every sphere's position, velocity and spin after
// the step, keeping the last good state (a Snapshot) so a bad step can be undone and saved.
// Decision: the check runs once per step, not after every system; only when it fires is the
// step replayed from the last good state system by system, to name the system at fault.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "engine/entity.h"
#include "engine/error.h"
#include "engine/snapshot.h"

namespace ballpit {

class FixedStepLoop;
class Scheduler;
class World;

struct NonFiniteValue {
  Entity entity;
  std::string field;  // "position", "velocity" or "angular_velocity"
};

// The non-finite value in the lowest row (deterministic whatever the thread count), if any.
std::optional<NonFiniteValue> find_non_finite(const World& world);

// Thrown by NanGuard::step; what() names the entity, the field, the step and the system.
class NonFiniteState : public Error {
 public:
  using Error::Error;
};

class NanGuard {
 public:
  // Captures the current state as the first good one; throws ballpit::Error if it already holds
  // a non-finite value or state snapshots cannot store (a character).
  explicit NanGuard(const World& world);

  // The check, one loop step, the check again. On a non-finite value, throws NonFiniteState naming the
  // entity and the first system after which the value appears (replayed on a copy); the world
  // is left as the bad step made it, and last_good() holds the state before that step.
  void step(FixedStepLoop& loop, World& world, Scheduler& scheduler);
  // The two halves of step(), for a caller that times the step alone.
  void before_step(const World& world) const;
  void after_step(const World& world, Scheduler& scheduler);

  const Snapshot& last_good() const { return last_good_; }

 private:
  std::string locate(Scheduler& scheduler, const NonFiniteValue& bad) const;

  Snapshot last_good_;
};

}  // namespace ballpit
