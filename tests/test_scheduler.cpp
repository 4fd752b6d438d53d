// The scheduler's contract: conflicting systems run in registration order, independent ones
// may run at once, errors reach the caller, and (debug builds) undeclared access is caught.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "engine/error.h"
#include "engine/scheduler.h"
#include "engine/thread_share.h"
#include "engine/world.h"

using namespace ballpit;

namespace {

class FnSystem : public System {
 public:
  FnSystem(std::string name, Access access, std::function<void(World&)> fn, bool data_parallel = false)
      : name_(std::move(name)), access_(access), fn_(std::move(fn)), data_parallel_(data_parallel) {}
  std::string_view name() const override { return name_; }
  Access access() const override { return access_; }
  void run(World& w) override { fn_(w); }
  bool data_parallel() const override { return data_parallel_; }

 private:
  std::string name_;
  Access access_;
  std::function<void(World&)> fn_;
  bool data_parallel_;
};

Access reads(ColumnSet r) { return {r, {}}; }
Access writes(ColumnSet w) { return {{}, w}; }

}  // namespace

TEST(Scheduler, ConflictingSystemsRunInRegistrationOrder) {
  World world;
  Scheduler s(2);
  std::mutex m;
  std::vector<std::string> order;
  auto log = [&](const char* n) {
    return [&, n](World&) {
      std::lock_guard lock(m);
      order.push_back(n);
    };
  };
  s.add(std::make_unique<FnSystem>("write_v", writes({ColumnId::SphereVelocity}), log("write_v")));
  s.add(std::make_unique<FnSystem>("read_v_write_x",
                                   Access{{ColumnId::SphereVelocity}, {ColumnId::SpherePosition}}, log("read_v_write_x")));
  s.add(std::make_unique<FnSystem>("read_x", reads({ColumnId::SpherePosition}), log("read_x")));
  for (int frame = 0; frame < 50; ++frame) {
    order.clear();
    s.run_frame(world);
    ASSERT_EQ(order, (std::vector<std::string>{"write_v", "read_v_write_x", "read_x"}));
  }
  EXPECT_EQ(s.predecessors(2), (std::vector<std::size_t>{1}));  // read_x waits only for the writer of x
}

TEST(Scheduler, ReadersOfTheSameColumnDoNotWaitForEachOther) {
  Scheduler s(2);
  s.add(std::make_unique<FnSystem>("a", reads({ColumnId::SpherePosition}), [](World&) {}));
  s.add(std::make_unique<FnSystem>("b", reads({ColumnId::SpherePosition}), [](World&) {}));
  EXPECT_TRUE(s.predecessors(1).empty());
}

TEST(Scheduler, IndependentSystemsOverlapInTime) {
  World world;
  Scheduler s(2);
  // Each system waits (bounded) for the other to start: they can only both see 2 if they
  // run at the same time.
  std::atomic<int> started{0};
  std::atomic<int> saw_both{0};
  auto rendezvous = [&](World&) {
    ++started;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    if (started.load() >= 2) ++saw_both;
  };
  s.add(std::make_unique<FnSystem>("a", writes({ColumnId::SpherePosition}), rendezvous));
  s.add(std::make_unique<FnSystem>("b", writes({ColumnId::SphereColor}), rendezvous));
  s.run_frame(world);
  EXPECT_EQ(saw_both.load(), 2);
}

// A data-parallel system (one that runs OpenMP loops) runs on run_frame's thread only, whichever
// thread made it ready, while the workers still take the other systems beside it. The graph: two
// serial systems ready at the start, one of them beside a data-parallel one and one before a
// second data-parallel one, which the worker that finishes its predecessor must leave to the
// caller's thread (and wake it for).
TEST(Scheduler, DataParallelSystemsRunOnTheCallersThreadAndOthersBesideThem) {
  World world;
  Scheduler s(2);
  const std::thread::id caller = std::this_thread::get_id();
  std::mutex m;
  std::vector<std::thread::id> parallel_threads;
  std::atomic<int> serial_on_worker{0};
  auto parallel = [&](World&) {
    std::lock_guard lock(m);
    parallel_threads.push_back(std::this_thread::get_id());
  };
  auto serial = [&](World&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // time for a worker to wake and take the other
    if (std::this_thread::get_id() != caller) ++serial_on_worker;
  };
  s.add(std::make_unique<FnSystem>("serial_a", writes({ColumnId::SphereColor}), serial));
  s.add(std::make_unique<FnSystem>("parallel_x", writes({ColumnId::SpherePosition}), parallel, true));
  s.add(std::make_unique<FnSystem>("serial_b", writes({ColumnId::Colliders}), serial));
  s.add(std::make_unique<FnSystem>("parallel_after_b", Access{{ColumnId::Colliders}, {ColumnId::SphereVelocity}},
                                   parallel, true));
  const int frames = 200;
  for (int frame = 0; frame < frames; ++frame) s.run_frame(world);
  ASSERT_EQ(parallel_threads.size(), 2u * frames);
  for (const std::thread::id& id : parallel_threads) EXPECT_EQ(id, caller);
  // The caller takes a data-parallel system first, so a worker takes the serial ones most frames.
  EXPECT_GT(serial_on_worker.load(), frames / 2);
}

// A system that starts OpenMP loops without declaring it (data_parallel) must not start a
// second team on a worker, beside the caller's: a worker runs its loops on one thread. The
// process's default team must be larger for this to show (the name's ending has ctest run it
// with OMP_NUM_THREADS=2, tests/CMakeLists.txt).
TEST(Scheduler, AWorkerRunsAnUndeclaredSystemsOpenMPLoopsOnOneThread_UnderTwoOpenMPThreads) {
  const int default_team = [] {
    int team = 0;
    std::thread([&] { team = omp_get_max_threads(); }).join();
    return team;
  }();
  if (default_team < 2) GTEST_SKIP() << "needs a default OpenMP team of 2 or more (OMP_NUM_THREADS=" << default_team << ")";
  World world;
  Scheduler s(2);
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> undeclared_started{false};
  std::atomic<int> caller_team{0}, worker_team{0}, worker_runs{0};
  // The caller takes the declared system first and holds it until the other has started, so a
  // worker runs the undeclared one.
  auto declared = [&](World&) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!undeclared_started && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
#pragma omp parallel
#pragma omp single
    caller_team = omp_get_num_threads();
  };
  auto undeclared = [&](World&) {
    undeclared_started = true;
    if (std::this_thread::get_id() == caller) return;
    ++worker_runs;
#pragma omp parallel
#pragma omp single
    worker_team = std::max(worker_team.load(), omp_get_num_threads());
  };
  s.add(std::make_unique<FnSystem>("declared", writes({ColumnId::SpherePosition}), declared, true));
  s.add(std::make_unique<FnSystem>("undeclared", writes({ColumnId::SphereColor}), undeclared));
  const TeamSize team(2);
  for (int frame = 0; frame < 20; ++frame) {
    undeclared_started = false;
    s.run_frame(world);
  }
  ASSERT_GT(worker_runs.load(), 0);
  EXPECT_EQ(caller_team.load(), 2);
  EXPECT_EQ(worker_team.load(), 1);
}

TEST(Scheduler, AnExceptionInASystemReachesTheCallerAndLaterSystemsDoNotRun) {
  World world;
  Scheduler s(2);
  bool later_ran = false;
  s.add(std::make_unique<FnSystem>("fails", writes({ColumnId::SpherePosition}),
                                   [](World&) { throw Error("boom in fails"); }));
  s.add(std::make_unique<FnSystem>("after", reads({ColumnId::SpherePosition}), [&](World&) { later_ran = true; }));
  try {
    s.run_frame(world);
    FAIL() << "expected the system's error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "boom in fails");
  }
  EXPECT_FALSE(later_ran);
  // The scheduler is usable again after a failed frame.
  Scheduler ok(2);
  ok.add(std::make_unique<FnSystem>("fine", reads({ColumnId::SpherePosition}), [](World&) {}));
  EXPECT_NO_THROW(ok.run_frame(world));
}

TEST(Scheduler, TimesEverySystemRun) {
  World world;
  Scheduler s(1);
  s.add(std::make_unique<FnSystem>("sleepy", writes({ColumnId::SpherePosition}),
                                   [](World&) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); }));
  for (int i = 0; i < 5; ++i) s.run_frame(world);
  auto stats = s.profiler().stats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].name, "sleepy");
  EXPECT_EQ(stats[0].frames, 5u);
  EXPECT_GE(stats[0].median_ms, 2.0);  // sleep_for sleeps at least this long
}

#ifndef NDEBUG
TEST(Scheduler, UndeclaredColumnAccessIsCaughtInDebugBuilds) {
  World world;
  Scheduler s(1);
  s.add(std::make_unique<FnSystem>("sneaky", reads({ColumnId::SpherePosition}),
                                   [](World& w) { (void)w.spheres.mut_velocity(); }));
  EXPECT_THROW(s.run_frame(world), Error);
}
#endif
