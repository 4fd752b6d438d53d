// Worlds the per-system benchmarks run on, made on demand and kept for the process, so every
// benchmark of one size starts from the same state and pays its preparation once.
//
// Two kinds, both in the canonical pour pit (shared/SCENES.md: r = 0.04 m, 0.05 kg, e = 0.5,
// friction 0.5, L = sqrt(N * 5.6e-4) m):
// - packed: a synthetic settled pit, spheres on a cubic lattice of spacing 2r, just touching,
//   about 0.9 m deep. It is at rest from the first step (a perfect lattice under gravity stays
//   a lattice), so it is cheap to make at 1M spheres and every benchmark iteration sees the
//   same work: three resting contacts per sphere, about what a random settled pile has.
// - settled: the real pour run for kSettleSteps steps. Contact counts and memory order are
//   those of a real pile; making it costs the pour itself, so by default only N <= 10,000
//   (BALLPIT_BENCH_SETTLED_MAX raises the limit; there is no snapshot format yet).
// Both have taken full steps before they are handed out, so the grid, the contact lists and
// the warm-start cache are those of a running simulation.
#pragma once

#include <cstddef>
#include <string_view>

#include "engine/world.h"

namespace ballpit::profiling {

enum class PreparedKind { Packed, Settled };

inline constexpr int kSettleSteps = 300;  // 5 s of pour: the pile has collapsed by ~1 s
inline constexpr int kPackedWarmSteps = 3;

std::string_view kind_name(PreparedKind kind);

// Copy the returned world; it stays cached until a different (kind, n) is asked for, so a
// process holds at most one prepared world besides the copy it benchmarks.
const World& prepared_world(PreparedKind kind, std::size_t n);

// Largest N for which the settled kind is made (BALLPIT_BENCH_SETTLED_MAX, default 10,000).
std::size_t settled_max_spheres();

// The synthetic packed pit before any step.
World make_packed_world(std::size_t n);

// Runs `steps` full physics steps (grid, narrowphase, solver, and sleeping if enabled) on
// `threads` threads.
void step_world(World& world, int steps, int threads);

}  // namespace ballpit::profiling
