// engine/thread_share.h: the threads' shares of a loop are contiguous, in thread order, cover
// every item exactly once, and are about equal in cost; small work gets a small team.
#include <gtest/gtest.h>
#include <omp.h>
#include <strings.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

#include "engine/thread_share.h"

using namespace ballpit;

namespace {

// The cost of items [0, k) at k.
std::vector<std::size_t> costs_before(const std::vector<std::size_t>& cost) {
  std::vector<std::size_t> before(cost.size() + 1, 0);
  for (std::size_t k = 0; k < cost.size(); ++k) before[k + 1] = before[k] + cost[k];
  return before;
}

// Thread t's share of 2 for items with these costs.
std::pair<int, int> half(int t, const std::vector<std::size_t>& cost) {
  const std::vector<std::size_t> before = costs_before(cost);
  return share_of(t, 2, static_cast<int>(cost.size()), [&](int k) { return before[static_cast<std::size_t>(k)]; });
}

// Checks the shares of items with these costs among `threads` threads.
void expect_fair_shares(const std::vector<std::size_t>& cost, int threads) {
  const std::vector<std::size_t> before = costs_before(cost);
  const int count = static_cast<int>(cost.size());
  const std::size_t total = before.back();
  const std::size_t largest = cost.empty() ? 0 : *std::max_element(cost.begin(), cost.end());
  int next = 0;
  for (int t = 0; t < threads; ++t) {
    const auto [first, last] =
        share_of(t, threads, count, [&](int k) { return before[static_cast<std::size_t>(k)]; });
    EXPECT_EQ(first, next) << "thread " << t << " of " << threads << ": shares must be contiguous";
    EXPECT_LE(first, last) << "thread " << t;
    // Each share starts and ends at the item boundaries nearest to its fraction of the total,
    // so it holds at most that fraction plus half an item at either end.
    EXPECT_LE(before[last] - before[first], total / threads + largest + 1) << "thread " << t << " of " << threads;
    next = last;
  }
  EXPECT_EQ(next, count) << threads << " threads must cover every item";
}

TEST(ThreadShare, EqualCostsSplitEvenly) {
  const std::vector<std::size_t> cost(12, 5);
  const auto [a0, a1] = share_of(0, 2, 12, [&](int k) { return std::size_t(5) * k; });
  const auto [b0, b1] = share_of(1, 2, 12, [&](int k) { return std::size_t(5) * k; });
  EXPECT_EQ(a0, 0);
  EXPECT_EQ(a1, 6);
  EXPECT_EQ(b0, 6);
  EXPECT_EQ(b1, 12);
  for (int threads = 1; threads <= 5; ++threads) expect_fair_shares(cost, threads);
}

TEST(ThreadShare, APileAgainstOneWallIsSplitByCostNotCount) {
  // A pile pushed against one wall: its two slabs hold most of the contacts.
  const std::vector<std::size_t> cost = {100, 100, 1, 1, 1, 1, 1, 1, 1, 1};
  // 100 of 208 before item 1, 200 before item 2: the first thread's share ends at item 1, the
  // boundary nearest half the cost (by count it would take five).
  EXPECT_EQ(half(0, cost), std::make_pair(0, 1));
  EXPECT_EQ(half(1, cost), std::make_pair(1, 10));
  expect_fair_shares(cost, 2);
  expect_fair_shares(cost, 3);
}

TEST(ThreadShare, EmptyAndCostlessItemsStillGetAThread) {
  expect_fair_shares({}, 1);
  expect_fair_shares({}, 4);
  expect_fair_shares({0, 0, 0}, 2);       // nothing to do: the last thread takes all
  expect_fair_shares({7, 0, 0, 0}, 3);    // trailing items that cost nothing
  expect_fair_shares({0, 0, 9, 0, 0}, 2);
  const auto [first, last] = share_of(1, 2, 3, [](int) { return std::size_t{0}; });
  EXPECT_EQ(first, 0);
  EXPECT_EQ(last, 3);
}

TEST(ThreadShare, RandomCostsAndTeamSizes) {
  std::mt19937 rng(2026);
  std::uniform_int_distribution<int> size(0, 64), team(1, 9);
  std::uniform_int_distribution<std::size_t> item(0, 1000);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<std::size_t> cost(static_cast<std::size_t>(size(rng)));
    for (std::size_t& c : cost) c = item(rng);
    expect_fair_shares(cost, team(rng));
  }
}

TEST(ThreadShare, ShareEndsAtTheNearestBoundary) {
  // Half of the cost lies inside item 2: the first thread's share ends at whichever of its
  // boundaries is nearer half (the first past it would take item 2 whatever its cost).
  // Boundary after item 1 (20 of 51) is 5.5 from half, after item 2 (50) 24.5: it ends at 2.
  EXPECT_EQ(half(0, {10, 10, 30, 1}), std::make_pair(0, 2));
  EXPECT_EQ(half(1, {10, 10, 30, 1}), std::make_pair(2, 4));
  // Equally near (20 and 30 of 50): the later boundary.
  EXPECT_EQ(half(0, {10, 10, 10, 20}), std::make_pair(0, 3));
}

TEST(ThreadShare, MoreThreadsThanItems) {
  expect_fair_shares({3, 4}, 8);
}

TEST(ThreadShare, SmallWorkGetsASmallTeam) {
  omp_set_num_threads(2);
  EXPECT_EQ(team_for(0, 1024), 1);
  EXPECT_EQ(team_for(2047, 1024), 1);
  EXPECT_EQ(team_for(2048, 1024), 2);
  EXPECT_EQ(team_for(std::size_t{1} << 30, 1024), 2);  // never more than the caller's team
  {
    const TeamSize one(team_for(100, 1024));
    int seen = 0;
#pragma omp parallel
    {
#pragma omp single
      seen = omp_get_num_threads();
    }
    EXPECT_EQ(seen, 1);
  }
  EXPECT_EQ(omp_get_max_threads(), 2) << "TeamSize gives the caller its team size back";
}

TEST(ThreadShare, PassiveWaitsAskMoreWorkOfAThread) {
  omp_set_num_threads(2);
  const PerThread per_thread{.spinning = 1000, .passive = 4000};
  EXPECT_EQ(per_thread.when(false), 1000u);
  EXPECT_EQ(per_thread.when(true), 4000u);
  EXPECT_EQ(team_for(2000, per_thread.when(false)), 2);
  EXPECT_EQ(team_for(2000, per_thread.when(true)), 1);
  EXPECT_EQ(team_for(7999, per_thread.when(true)), 1);
  EXPECT_EQ(team_for(8000, per_thread.when(true)), 2);
  // The policy is the one the OpenMP runtime was given (the tests run passive: scripts/test.sh;
  // a bare ctest leaves it unset), in any case, as GNU OpenMP reads it.
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  const bool passive = policy != nullptr && strcasecmp(policy, "passive") == 0;
  EXPECT_EQ(threads_wait_passively(), passive);
  EXPECT_EQ(team_for(2000, per_thread), passive ? 1 : 2);
}

TEST(ThreadShare, FullTeamsGiveEveryThreadToAnyWork) {
  omp_set_num_threads(2);
  {
    const FullTeams outer;
    {
      const FullTeams inner;
      EXPECT_EQ(team_for(1, 1024), 2);
    }
    EXPECT_EQ(team_for(0, PerThread{1024, 4096}), 2) << "the outer scope still holds";
    omp_set_num_threads(1);
    EXPECT_EQ(team_for(1 << 20, 1024), 1) << "never more than the caller's team";
    omp_set_num_threads(2);
  }
  EXPECT_EQ(team_for(1, 1024), 1);
}

}  // namespace
