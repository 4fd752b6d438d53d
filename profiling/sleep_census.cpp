// Why spheres are awake (issue 39): runs a scene or a snapshot as `ballpit run` does and, every
// --every steps, counts the awake spheres by what keeps them awake and by how far they are from
// the nearest joint collider. One JSON line per census on stdout, the run's report line last.
//
// What keeps a sphere awake, checked in this order (systems/sleeping.cpp):
// - moving: faster than wake_speed (it keeps the regions it may reach from falling asleep, and
//   past kApproachWakeFactor times that it wakes them);
// - slow: faster than sleep_speed, not past wake_speed;
// - drifting: slower than sleep_speed but its still clock was restarted by the drift rule or has
//   not yet run sleep_time;
// - held: still for sleep_time, but its region is restless: by a sphere in it not yet still
//   (held_by_unstill), or else by motion that may reach it or a deep contact in or next to it
//   (held_otherwise). A column sleeps under its lowest unstill sphere (systems/sleep_regions.h:
//   kSleepBelowDiameters), so unstill_by_depth counts them by their depth under its top.
//
//   sleep_census --load pit.snap --steps 600 --every 30
//   sleep_census --scene scenes/pit_character.json --set features.sleeping=true ...
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>

#include "app/headless_run.h"
#include "engine/error.h"
#include "engine/world.h"
#include "systems/sleep_regions.h"

namespace {

using namespace ballpit;

// Distance bins from the nearest collider's surface (unit: m): the limbs' reach, a stride, the
// pile around him, the rest of the pit.
constexpr std::array<float, 4> kBinEdges = {0.25f, 0.5f, 1.0f, 2.0f};

float segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const float len2 = ab.squaredNorm();
  const float t = len2 > 0.0f ? std::clamp((p - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
  return (p - (a + t * ab)).norm();
}

struct Census {
  std::size_t awake = 0, moving = 0, slow = 0, drifting = 0, held = 0, held_by_unstill = 0;
  std::array<std::size_t, kBinEdges.size() + 1> by_distance{}, moving_by_distance{};
  std::array<std::size_t, 4> moving_by_speed{};  // wake_speed x (1-2, 2-4, 4-8, over 8)
  std::array<std::size_t, 4> unstill_by_depth{};  // under the column's top, diameters: 0-2, 2-4, 4-8, over 8
  double mean_height_m = 0.0;  // of every sphere along -gravity: a pile that sags sinks it
};

// The deepest overlap among the step's listed sphere pairs (sleeper pairs are not listed: they
// did not move), of all of them and of those with a sphere that was asleep in the step:
// `was_asleep` by entity index, as the step began (a sleeper pressed deep wakes after it).
struct PairOverlaps {
  float worst_r = 0.0f, worst_with_sleeper_r = 0.0f;
};
PairOverlaps worst_pair_overlaps(const World& world, const std::vector<std::uint8_t>& was_asleep) {
  const auto x = world.spheres.position();
  const auto r = world.spheres.radius();
  auto slept = [&](std::uint32_t row) {
    const std::uint32_t e = world.spheres.entity_at(row).index;
    return e < was_asleep.size() && was_asleep[e];
  };
  PairOverlaps worst;
  auto visit = [&](const Contact& c) {
    if (c.b & kTagMask) return;
    const float depth = (r[c.a] + r[c.b] - (x[c.a] - x[c.b]).norm()) / std::min(r[c.a], r[c.b]);
    worst.worst_r = std::max(worst.worst_r, depth);
    if (depth > worst.worst_with_sleeper_r && (slept(c.a) || slept(c.b))) worst.worst_with_sleeper_r = depth;
  };
  for (const SlabContacts& slab : world.contacts.slabs) {
    for (const Contact& c : slab.pairs) visit(c);
    for (const Contact& c : slab.serial) visit(c);
  }
  return worst;
}

// Each sphere's sleep state by entity index, to follow it across the grid's reorders.
void asleep_by_entity(const World& world, std::vector<std::uint8_t>& out) {
  const auto asleep = world.spheres.asleep();
  for (std::uint32_t i = 0; i < asleep.size(); ++i) {
    const std::uint32_t e = world.spheres.entity_at(i).index;
    if (e >= out.size()) out.resize(e + 1, 0);
    out[e] = asleep[i];
  }
}

Census take_census(const World& world) {
  Census c;
  const auto x = world.spheres.position();
  const auto v = world.spheres.velocity();
  const auto asleep = world.spheres.asleep();
  const auto still = world.spheres.still_time();
  const auto ca = world.colliders.a();
  const auto cb = world.colliders.b();
  const auto cr = world.colliders.radius();
  const SolverSettings& s = world.solver;
  // Each region's lowest sphere not yet still for sleep_time (systems/sleeping.cpp: restless).
  const SleepRegions regions(world.pit, world.gravity(), world.grid.max_radius);
  Levels unstill(regions.size(), kNoLevel);
  Levels top(regions.size(), -kNoLevel);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::uint32_t k = regions.of(x[i]);
    c.mean_height_m += regions.height(x[i]) / static_cast<double>(x.size());
    top[k] = std::max(top[k], regions.height(x[i]));
    if (!asleep[i] && still[i] < s.sleep_time) SleepRegions::lower(unstill[k], regions.height(x[i]));
  }
  // Where in their columns the unstill spheres lie: a column sleeps only under its lowest.
  const float diameter = 2.0f * world.grid.max_radius;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (asleep[i] || still[i] >= s.sleep_time) continue;
    const float depth = (top[regions.of(x[i])] - regions.height(x[i])) / diameter;
    ++c.unstill_by_depth[depth < 2.0f ? 0 : depth < 4.0f ? 1 : depth < 8.0f ? 2 : 3];
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (asleep[i]) continue;
    ++c.awake;
    const float speed = v[i].norm();
    if (speed > s.wake_speed) ++c.moving;
    else if (speed > s.sleep_speed) ++c.slow;
    else if (still[i] < s.sleep_time) ++c.drifting;
    else {
      ++c.held;
      if (!regions.sleeps_under(unstill[regions.of(x[i])], regions.height(x[i]))) ++c.held_by_unstill;
    }
    float d = std::numeric_limits<float>::infinity();
    for (std::size_t k = 0; k < world.colliders.size(); ++k) d = std::min(d, segment_distance(x[i], ca[k], cb[k]) - cr[k]);
    std::size_t bin = 0;
    while (bin < kBinEdges.size() && d > kBinEdges[bin]) ++bin;
    ++c.by_distance[bin];
    if (speed > s.wake_speed) {
      ++c.moving_by_distance[bin];
      const float f = speed / s.wake_speed;
      ++c.moving_by_speed[f < 2.0f ? 0 : f < 4.0f ? 1 : f < 8.0f ? 2 : 3];
    }
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) try {
  RunOptions run;
  run.progress = false;
  run.print_table = false;
  int every = 30;
  CLI::App app{"Counts the awake spheres by what keeps them awake (issue 39)"};
  app.add_option("--scene", run.scene, "Scene name or file");
  app.add_option("--set", run.set, "key.path=value overrides of the scene");
  app.add_option("--load", run.load_path, "Resume from this snapshot");
  app.add_option("--steps", run.steps, "Steps to run")->check(CLI::PositiveNumber);
  app.add_option("--threads", run.threads, "Threads")->check(CLI::PositiveNumber);
  app.add_option("--every", every, "Steps between censuses")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  // The deepest overlaps are taken after every step, the census every `every` steps; each line
  // gives the worst since the line before.
  int step = 0;
  std::vector<std::uint8_t> was_asleep;
  PairOverlaps worst;
  run.after_step = [&](const World& world) {
    ++step;
    if (was_asleep.empty()) asleep_by_entity(world, was_asleep);  // the first step: as it ended
    const PairOverlaps now = worst_pair_overlaps(world, was_asleep);
    worst.worst_r = std::max(worst.worst_r, now.worst_r);
    worst.worst_with_sleeper_r = std::max(worst.worst_with_sleeper_r, now.worst_with_sleeper_r);
    asleep_by_entity(world, was_asleep);
    if (step % every) return;
    const Census c = take_census(world);
    nlohmann::ordered_json j;
    j["step"] = step;
    j["awake"] = c.awake;
    j["moving"] = c.moving;
    j["slow"] = c.slow;
    j["drifting"] = c.drifting;
    j["held_by_unstill"] = c.held_by_unstill;
    j["held_otherwise"] = c.held - c.held_by_unstill;
    j["near_0.25m"] = c.by_distance[0];
    j["near_0.5m"] = c.by_distance[1];
    j["near_1m"] = c.by_distance[2];
    j["near_2m"] = c.by_distance[3];
    j["beyond_2m"] = c.by_distance[4];
    j["moving_by_distance"] = c.moving_by_distance;
    j["moving_by_speed"] = c.moving_by_speed;
    j["unstill_by_depth"] = c.unstill_by_depth;
    j["mean_height_m"] = c.mean_height_m;
    j["worst_pair_r"] = worst.worst_r;
    j["worst_pair_with_sleeper_r"] = worst.worst_with_sleeper_r;
    worst = {};
    std::cout << j.dump() << std::endl;
  };
  std::cout << run_headless(run).dump() << std::endl;
  return 0;
} catch (const ballpit::Error& e) {
  std::fprintf(stderr, "sleep_census: %s\n", e.what());
  return 1;
}
