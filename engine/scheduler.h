// Runs a frame of systems from their declared accesses. System j depends on an earlier-added
// system i exactly when their accesses conflict; systems with no path between them may run at
// the same time on the scheduler's workers. The caller's thread is one of the workers. An
// exception thrown by a system stops new systems from starting, lets running ones finish, and
// is rethrown to the caller of run_frame.
//
// Systems that run OpenMP loops (System::data_parallel) run on the caller's thread only. OpenMP
// keeps a team of threads for each thread that starts parallel loops, and an idle team's threads
// spin a while before they sleep (GNU OpenMP's default wait). When the pit's systems ran on
// whichever thread made them ready, a frame's narrowphase and solver often ran in the worker's
// team while the caller's team, fresh from the grid, spun beside it: four busy threads on two
// cores. The 100k pit-character's solver took 33.5 ms a step; on the caller's thread alone,
// 30.4 (600 steps, 2 threads). The workers take the systems without such loops (the
// character's) alongside, and a worker's own parallel loops, should an undeclared system start
// any, run one thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "engine/profiler.h"
#include "engine/system.h"

namespace ballpit {

class Scheduler {
 public:
  // `concurrency` systems may run at once (>= 1); the caller's thread counts as one.
  explicit Scheduler(int concurrency = 2);
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  // Registration order is the tie-break between conflicting systems.
  System& add(std::unique_ptr<System> system);
  template <class T, class... Args>
  T& emplace(Args&&... args) {
    return static_cast<T&>(add(std::make_unique<T>(std::forward<Args>(args)...)));
  }
  void clear();

  void run_frame(World& world);

  std::size_t size() const { return systems_.size(); }
  System& system(std::size_t i) { return *systems_[i]; }
  const System& system(std::size_t i) const { return *systems_[i]; }
  // Indices of the systems i must wait for (direct predecessors only).
  const std::vector<std::size_t>& predecessors(std::size_t i);
  Profiler& profiler() { return profiler_; }
  const Profiler& profiler() const { return profiler_; }

 private:
  void build_graph();
  void worker_loop();
  void run_one(std::size_t i, World& world);
  std::size_t next_ready(bool caller) const;
  bool execute_ready(std::unique_lock<std::mutex>& lock, bool caller);

  std::vector<std::unique_ptr<System>> systems_;
  std::vector<Access> accesses_;
  std::vector<bool> data_parallel_;
  std::vector<std::vector<std::size_t>> successors_;
  std::vector<std::vector<std::size_t>> predecessors_;
  bool graph_dirty_ = true;

  // Frame state, guarded by mutex_.
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::size_t> waiting_on_;  // unfinished predecessors per system
  std::vector<std::size_t> ready_;
  std::size_t unfinished_ = 0;
  std::size_t running_ = 0;
  World* world_ = nullptr;
  std::exception_ptr error_;
  bool stop_workers_ = false;
  bool caller_waiting_ = false;  // run_frame's caller sleeps until the frame ends or fails
  std::uint64_t frame_id_ = 0;

  std::vector<std::thread> workers_;
  Profiler profiler_;
};

}  // namespace ballpit
