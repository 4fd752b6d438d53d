// The NaN guard: steps the world and checks every sphere's position, velocity and spin after
// the step, so that a bad step can be undone and saved: it names the last good state (a
// Snapshot) when the check fires.
// Decision: the check runs once per step, not after every system; only when it fires is the
// step replayed from the last good state system by system, to name the system at fault.
// Decision: a checkpoint every kCheckpointSteps steps, not a snapshot of the whole world after
// every step: that copy cost a settled 1M pit 20 ms a step, twice the step (issue 39: only what
// moves costs). When the check fires, the steps since the checkpoint are replayed (the engine
// is deterministic) to rebuild the state before the bad step, and the bad step once more to
// check that the replay comes back to the world's state hash: it does where only the loop
// changes the world between steps, as in `ballpit run`; where it does not, the error says so
// and the checkpoint stands as the last good state.
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

  // After step() or after_step() threw NonFiniteState: the state before the bad step. Before,
  // the latest checkpoint.
  const Snapshot& last_good() const { return failed_ ? last_good_ : checkpoint_; }

  // Steps between checkpoints: a capture costs about as much as a settled pit's step, and a
  // bad step costs at most this many steps again to replay (half a second at 60 Hz).
  static constexpr int kCheckpointSteps = 30;

 private:
  std::string locate(Scheduler& scheduler, const NonFiniteValue& bad) const;
  // Sets last_good_; returns "" or why the checkpoint stands in for it.
  std::string replay_to_last_good(const World& world, Scheduler& scheduler);

  Snapshot checkpoint_, last_good_;
  int steps_since_checkpoint_ = 0;  // good steps since checkpoint_ was captured
  bool failed_ = false;             // last_good_ holds the state before a bad step
};

}  // namespace ballpit
