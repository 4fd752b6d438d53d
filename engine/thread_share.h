// How a system spreads its work over OpenMP threads: contiguous shares of a loop's items, of
// about equal cost, and a team no larger than the work is worth.
//
// A system whose items lie in space (grid slabs, groups of slabs) and that runs every step, or
// several times a step, wants each thread to take the same stretch of items each time: the
// bodies and contacts it touched last time are still in its core's cache. schedule(dynamic)
// hands each item to whichever thread asks first, so every pass moves about half of the working
// set from one core's cache to the other's; in the contact solver at 10k spheres that made 2
// threads spend twice the CPU time of 1 (systems/solver.cpp). schedule(static) keeps the
// stretches but splits by count, not cost. Where the work goes never changes a result here: the
// systems that use this are deterministic for any split.
#pragma once

#include <strings.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <utility>

#include <omp.h>

namespace ballpit {

// Items [first, last) of thread `thread` of `threads`, for `count` items whose cost up to item
// k is cost_before(k), non-decreasing, from cost_before(0) = 0 to the total at k = count. Thread
// t starts at the item boundary nearest to t/threads of the total cost (on a tie, the later
// one), so the shares are contiguous, in thread order, cover every item once, and each costs at
// most total/threads plus one item more. Nearest rather than first past: with a few dozen slabs
// a thread, the first boundary past half gave the first of 2 threads up to a slab more, and on
// average half a slab more, than the other. Items that cost nothing at the end go to the last
// thread.
template <class CostBefore>
std::pair<int, int> share_of(int thread, int threads, int count, CostBefore&& cost_before) {
  const std::size_t total = cost_before(count);
  // Costs times threads, so that the targets t x total / threads are whole numbers.
  const std::size_t n = static_cast<std::size_t>(threads);
  auto scaled = [&](int k) { return cost_before(k) * n; };
  auto start_of = [&](int t) {
    if (t <= 0) return 0;
    if (t >= threads) return count;
    const std::size_t target = total * static_cast<std::size_t>(t);
    int lo = 0, hi = count;  // first k in [lo, hi] with scaled(k) >= target
    while (lo < hi) {
      const int mid = lo + (hi - lo) / 2;
      if (scaled(mid) < target) lo = mid + 1;
      else hi = mid;
    }
    if (lo > 0 && target - scaled(lo - 1) < scaled(lo) - target) --lo;
    return lo;
  };
  return {start_of(thread), start_of(thread + 1)};
}

// The calling thread's share inside an OpenMP parallel region.
template <class CostBefore>
std::pair<int, int> thread_share(int count, CostBefore&& cost_before) {
  return share_of(omp_get_thread_num(), omp_get_num_threads(), count, cost_before);
}

// The calling thread's share of `count` items of equal cost, inside an OpenMP parallel region.
inline std::pair<int, int> equal_share(int count) {
  return thread_share(count, [](int k) { return static_cast<std::size_t>(k); });
}

// Whether this process's OpenMP threads wait passively (OMP_WAIT_POLICY=passive, as
// scripts/run.sh, the reports and the tests set it; read once, as the OpenMP runtime reads it).
// A waiting thread then sleeps, and waking it for the next parallel region or past a barrier
// took 20 to 25 us on the KVM hosts measured, against under a microsecond for a spinning one:
// a team is worth that only on more work.
inline bool threads_wait_passively() {
  static const bool passive = [] {
    const char* policy = std::getenv("OMP_WAIT_POLICY");
    return policy != nullptr && strcasecmp(policy, "passive") == 0;
  }();
  return passive;
}

// Items (rows, contacts) worth a thread of their own where threads spin while they wait, and
// where they wait passively.
struct PerThread {
  std::size_t spinning;
  std::size_t passive;

  std::size_t when(bool waits_passively) const { return waits_passively ? passive : spinning; }
};

namespace detail {
inline std::atomic<int> full_teams{0};  // FullTeams alive
}

// The threads worth waking for `work` items when each should get at least `per_thread`, up to
// the calling thread's team size. Starting and ending a parallel region costs microseconds, and
// the solver runs about sixty a step: at 1k spheres, 2 threads took 1.6x the time of 1 for the
// whole step.
inline int team_for(std::size_t work, std::size_t per_thread) {
  const std::size_t most = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
  if (detail::full_teams.load(std::memory_order_relaxed) > 0) return static_cast<int>(most);
  return static_cast<int>(std::clamp<std::size_t>(work / per_thread, 1, most));
}

inline int team_for(std::size_t work, PerThread per_thread) {
  return team_for(work, per_thread.when(threads_wait_passively()));
}

// For its lifetime, every system takes the calling thread's whole team whatever its work, so a
// test's small world runs each parallel path that team_for would leave to one thread.
class FullTeams {
 public:
  FullTeams() { ++detail::full_teams; }
  ~FullTeams() { --detail::full_teams; }
  FullTeams(const FullTeams&) = delete;
  FullTeams& operator=(const FullTeams&) = delete;
};

// For its lifetime, the calling thread's parallel regions run `threads` threads (OpenMP's
// nthreads-var belongs to the calling thread, so systems run side by side by the scheduler do
// not see it).
class TeamSize {
 public:
  explicit TeamSize(int threads) : saved_(omp_get_max_threads()) { omp_set_num_threads(threads); }
  ~TeamSize() { omp_set_num_threads(saved_); }
  TeamSize(const TeamSize&) = delete;
  TeamSize& operator=(const TeamSize&) = delete;

 private:
  int saved_;
};

}  // namespace ballpit
