// Registration shared by the per-system benchmarks (bench_<system>.cpp): every system runs alone
// on a prepared world (profiling/prepared_world.h) of N = 1k, 10k, 100k and 1M spheres, at 1 and
// 2 threads. Google Benchmark's time column is wall time per call, i.e. per step of that
// system; the counters add ns_per_sphere (wall time / (calls x N)), the sphere count, and
// whatever the system adds (contacts).
//
// Names read "<system>/<kind>/n:<N>/threads:<T>", so --benchmark_filter='solver/packed/.*/threads:2'
// picks a slice.
#pragma once

#include <benchmark/benchmark.h>
#include <omp.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "engine/world.h"
#include "profiling/prepared_world.h"

namespace ballpit::profiling {

inline const std::vector<std::int64_t> kBenchSizes = {1000, 10000, 100000, 1000000};
inline const std::vector<std::int64_t> kBenchThreads = {1, 2};

// Runs `step` once per benchmark iteration, after one untimed warm-up call, and adds the
// per-sphere counter.
template <class F>
void timed_loop(benchmark::State& state, std::size_t n, F&& step) {
  step();  // warm-up: first-touch of scratch buffers is not what a running step pays
  auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) step();
  auto t1 = std::chrono::steady_clock::now();
  double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
  state.counters["ns_per_sphere"] = ns / (static_cast<double>(state.iterations()) * static_cast<double>(n));
  state.counters["spheres"] = static_cast<double>(n);
}

inline std::size_t contact_count(const World& w) {
  return w.contacts.count();
}

// Registers `body` for every kind, size and thread count. The body gets a fresh copy of the
// prepared world and the sphere count, and must call timed_loop.
inline bool register_system(const std::string& system,
                            std::function<void(benchmark::State&, World&, std::size_t)> body) {
  for (PreparedKind kind : {PreparedKind::Packed, PreparedKind::Settled}) {
    for (std::int64_t n : kBenchSizes) {
      if (kind == PreparedKind::Settled && static_cast<std::size_t>(n) > settled_max_spheres()) continue;
      std::string name = system + "/" + std::string(kind_name(kind));
      auto* b = benchmark::RegisterBenchmark(name.c_str(), [kind, body](benchmark::State& state) {
        const auto n_spheres = static_cast<std::size_t>(state.range(0));
        const int threads = static_cast<int>(state.range(1));
        World world = prepared_world(kind, n_spheres);
        omp_set_num_threads(threads);
        body(state, world, n_spheres);
      });
      for (std::int64_t t : kBenchThreads) b->Args({n, t});
      b->ArgNames({"n", "threads"})->UseRealTime()->Unit(benchmark::kMillisecond);
    }
  }
  return true;
}

}  // namespace ballpit::profiling
