#include "engine/scheduler.h"

#include <string>

#include <omp.h>

namespace ballpit {

Scheduler::Scheduler(int concurrency) {
  for (int i = 1; i < concurrency; ++i) workers_.emplace_back([this] { worker_loop(); });
}

Scheduler::~Scheduler() {
  {
    std::lock_guard lock(mutex_);
    stop_workers_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

System& Scheduler::add(std::unique_ptr<System> system) {
  accesses_.push_back(system->access());
  data_parallel_.push_back(system->data_parallel());
  systems_.push_back(std::move(system));
  graph_dirty_ = true;
  return *systems_.back();
}

void Scheduler::clear() {
  systems_.clear();
  accesses_.clear();
  data_parallel_.clear();
  graph_dirty_ = true;
}

void Scheduler::build_graph() {
  std::size_t n = systems_.size();
  successors_.assign(n, {});
  predecessors_.assign(n, {});
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < j; ++i)
      if (accesses_[i].conflicts_with(accesses_[j])) {
        successors_[i].push_back(j);
        predecessors_[j].push_back(i);
      }
  graph_dirty_ = false;
}

const std::vector<std::size_t>& Scheduler::predecessors(std::size_t i) {
  if (graph_dirty_) build_graph();
  return predecessors_[i];
}

void Scheduler::run_one(std::size_t i, World& world) {
  System& s = *systems_[i];
  AccessScope scope(&accesses_[i], s.name());
  auto start = Profiler::Clock::now();
  s.run(world);
  profiler_.record(std::string(s.name()), start, Profiler::Clock::now());
}

// Where in ready_ the system this thread takes next lies, ready_.size() if none: the latest
// one it may run, and for the caller's thread a data-parallel one first, which no worker may
// take.
std::size_t Scheduler::next_ready(bool caller) const {
  std::size_t any = ready_.size();
  for (std::size_t k = ready_.size(); k-- > 0;) {
    const bool parallel = data_parallel_[ready_[k]];
    if (caller && parallel) return k;
    if (!parallel && any == ready_.size()) any = k;
  }
  return any;
}

// Runs one ready system if there is one this thread may run; called with the lock held,
// returns with it held.
bool Scheduler::execute_ready(std::unique_lock<std::mutex>& lock, bool caller) {
  if (error_) return false;
  const std::size_t k = next_ready(caller);
  if (k == ready_.size()) return false;
  std::size_t i = ready_[k];
  ready_.erase(ready_.begin() + static_cast<std::ptrdiff_t>(k));
  ++running_;
  lock.unlock();
  std::exception_ptr failure;
  try {
    run_one(i, *world_);
  } catch (...) {
    failure = std::current_exception();
  }
  lock.lock();
  --running_;
  --unfinished_;
  if (failure) {
    if (!error_) error_ = failure;
  } else {
    for (std::size_t j : successors_[i])
      if (--waiting_on_[j] == 0) ready_.push_back(j);
  }
  // This thread takes the next ready system it may run itself: wake the others only for more
  // than that, and run_frame's caller only if it sleeps. A chain of dependent systems (the pit's
  // grid, narrowphase and solver) then wakes no thread.
  const std::size_t left_for_others = ready_.size() - (next_ready(caller) < ready_.size() ? 1 : 0);
  if (left_for_others > 0 || ((unfinished_ == 0 || error_) && caller_waiting_)) wake_.notify_all();
  return true;
}

void Scheduler::worker_loop() {
  // A system that runs OpenMP loops without saying so (data_parallel) runs them on this thread
  // alone: slower than declared, but never a second team spinning beside the caller's.
  omp_set_num_threads(1);
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_workers_ || (world_ && !error_ && next_ready(false) < ready_.size()); });
    if (stop_workers_) return;
    execute_ready(lock, false);
  }
}

void Scheduler::run_frame(World& world) {
  if (graph_dirty_) build_graph();
  profiler_.begin_frame();
  std::size_t n = systems_.size();
  {
    std::unique_lock lock(mutex_);
    waiting_on_.assign(n, 0);
    ready_.clear();
    for (std::size_t i = 0; i < n; ++i) waiting_on_[i] = predecessors_[i].size();
    // Ready systems are taken from the back: push in reverse so registration order leads.
    for (std::size_t i = n; i-- > 0;)
      if (waiting_on_[i] == 0) ready_.push_back(i);
    unfinished_ = n;
    running_ = 0;
    error_ = nullptr;
    world_ = &world;
    ++frame_id_;
    if (ready_.size() > 1) wake_.notify_all();  // one ready system: this thread runs it
    while (true) {
      if (execute_ready(lock, true)) continue;
      if (unfinished_ == 0 || (error_ && running_ == 0)) break;
      caller_waiting_ = true;
      wake_.wait(lock);
      caller_waiting_ = false;
    }
    world_ = nullptr;
  }
  profiler_.end_frame();
  if (error_) {
    std::exception_ptr e = error_;
    error_ = nullptr;
    std::rethrow_exception(e);
  }
}

}  // namespace ballpit
