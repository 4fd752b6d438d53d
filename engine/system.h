// A system: a named piece of per-step work that declares the columns it reads and writes. The
// declaration is the whole contract with the scheduler: it orders two systems exactly when
// their declarations conflict, in the order they were added.
#pragma once

#include <string_view>
#include <vector>

#include "engine/access.h"
#include "engine/memory_use.h"

namespace ballpit {

class World;

class System {
 public:
  virtual ~System() = default;
  virtual std::string_view name() const = 0;
  virtual Access access() const = 0;
  virtual void run(World& world) = 0;
  // Whether run() starts OpenMP parallel loops. The scheduler runs such a system on the thread
  // that calls run_frame, never on a worker (engine/scheduler.h); one that does not say so
  // may run on a worker, whose loops run one thread.
  virtual bool data_parallel() const { return false; }
  // What the system keeps on the heap between steps (its scratch), part by part, for the memory
  // breakdown (engine/memory_use.h).
  virtual std::vector<MemoryItem> held() const { return {}; }
};

}  // namespace ballpit
