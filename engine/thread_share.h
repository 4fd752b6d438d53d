// Contiguous shares of a loop's items for the threads of an OpenMP team, of about equal cost.
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

#include <cstddef>
#include <utility>

#include <omp.h>

namespace ballpit {

// Items [first, last) of thread `thread` of `threads`, for `count` items whose cost up to item
// k is cost_before(k), non-decreasing, from cost_before(0) = 0 to the total at k = count. Thread
// t starts at the first item with at least t/threads of the total cost before it, so the shares
// are contiguous, in thread order, cover every item once, and each costs at most
// total/threads plus one item more. Items that cost nothing at the end go to the last thread.
template <class CostBefore>
std::pair<int, int> share_of(int thread, int threads, int count, CostBefore&& cost_before) {
  const std::size_t total = cost_before(count);
  auto start_of = [&](int t) {
    if (t <= 0) return 0;
    if (t >= threads) return count;
    const std::size_t target = total * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
    int lo = 0, hi = count;  // first k in [lo, hi] with cost_before(k) >= target
    while (lo < hi) {
      const int mid = lo + (hi - lo) / 2;
      if (cost_before(mid) < target) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  };
  return {start_of(thread), start_of(thread + 1)};
}

// The calling thread's share inside an OpenMP parallel region.
template <class CostBefore>
std::pair<int, int> thread_share(int count, CostBefore&& cost_before) {
  return share_of(omp_get_thread_num(), omp_get_num_threads(), count, cost_before);
}

}  // namespace ballpit
