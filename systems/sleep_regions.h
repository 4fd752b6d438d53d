// Sleep regions: the pit cut into columns along gravity, square tiles across it, that fall asleep
// and wake each on its own (systems/sleeping.h), from the floor up: a column sleeps under its
// restless level (the lowest point that motion, an unstill sphere or a deep contact reaches in
// it), and wakes from its wake level (the lowest point a mover may reach) up. A region is a
// function of a position, not a stored thing: a sleeper never moves, so it stays in its region,
// and the regions may change shape (gravity turned, a larger ball added) whenever everything
// is awake.
// Decision: columns along gravity, asleep from the floor up, not cubes. A pile's weight runs down
// a column, so a column asleep next to an awake one only stops passing on the small sideways
// loads, and its sleeping bottom carries what rests on it as the fixed body it is (the struck
// wake wakes it when that load changes); a part asleep over an awake one would leave the one
// below it unloaded and restless. Whole columns, each waiting for its last unstill ball, kept
// 56,000 of the settled 100k pit awake on average while the marine walked; from the floor up,
// 46,000 (profiling/reports/sleeping.md, "Columns asleep from the floor up").
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "engine/math.h"
#include "engine/settings.h"

namespace ballpit {

// Whether there are spheres and every one sleeps (a step then has nothing to search, solve or sort), and whether
// any does: byte scans, a few hundredths of a millisecond per million spheres.
inline bool all_asleep(std::span<const std::uint8_t> asleep) {
  return !asleep.empty() && std::memchr(asleep.data(), 0, asleep.size()) == nullptr;
}
inline bool any_asleep(std::span<const std::uint8_t> asleep) {
  return !asleep.empty() && std::memchr(asleep.data(), 1, asleep.size()) != nullptr;
}

// Where the awake rows and the sleepers lie: every awake row is below awake_end, every sleeper
// at or past asleep_begin. The grid sorts the awake rows first (engine/spatial_grid.h), so from
// the grid to the sleep update the two meet, and a pass over one kind skips the other's rows
// whole; after spheres wake or fall asleep the spans overlap, and the passes stay right, only
// longer. Two byte scans.
struct RowSpans {
  std::size_t awake_end = 0, asleep_begin = 0;
  bool partitioned() const { return awake_end <= asleep_begin; }
};
inline RowSpans row_spans(std::span<const std::uint8_t> asleep) {
  const std::uint8_t* rows = asleep.data();
  const std::size_t n = asleep.size();
  const void* first_asleep = n ? std::memchr(rows, 1, n) : nullptr;
  const void* last_awake = n ? memrchr(rows, 0, n) : nullptr;
  return {last_awake ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(last_awake) - rows) + 1 : 0,
          first_asleep ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(first_asleep) - rows) : n};
}

// A region's width, in diameters of the largest sphere. Narrower regions wake less of the pit
// around a moving limb, but make more boundary between sleepers and awake spheres. The marine
// walking 2 s into a settled 100k pit kept 31,000 balls awake on average at 3 diameters, 61,000
// at 10 and 25,000 at 2 (issue 39's closing note).
inline constexpr float kSleepRegionDiameters = 3.0f;

// A sleeper struck by an awake sphere wakes its region after the step when the blow would have
// changed the striker's speed by more than this many times wake_speed. At once the wake speed,
// the load changes at the edge of an awake region woke a few thousand sleepers a step under the
// walking marine (a sphere's weight over a substep is 0.04 m/s of its speed), and the waking
// spread over most of the pit; a sleeper pressed deeper than the bound wakes anyway
// (systems/sleeping.cpp), whatever the blow.
inline constexpr float kStruckWakeFactor = 4.0f;

// A moving sphere wakes the sleeping regions it may reach in the coming step only when faster
// than this many times wake_speed; slower, a sleeper it meets stops it as the pile would (a
// fixed body with its loads kept), and the blow, at most the mover's own speed, stays under the
// struck wake above; a mover that comes to rest jammed into a sleeper wakes it (systems/
// sleeping.cpp, the pressed wake). Movers past wake_speed always keep the regions they may reach
// from falling asleep. At once the wake speed, the marine's footfalls woke the settled 100k pit
// 2 m around him through chains of movers at 5-10 cm/s: 75,000 balls awake on average over his
// path, against 56,000 at twice (the walking half 29.4 -> 21.0 ms a step), with pairs with a
// sleeper no deeper (0.026 r on average and 0.055 at worst, against 0.021 and 0.062;
// profiling/reports/sleeping.md, "What keeps balls awake"). At four times a stirred corner's
// pushed balls wandered into the sleeping pile past the regions that wake.
inline constexpr float kApproachWakeFactor = 2.0f;

// A column sleeps from the floor up to its restless level less this many diameters of the
// largest sphere: the spheres an unstill one rests on and the layer under them stay awake, and
// what lies deeper, still for sleep_time, sleeps under it. The marine's walk through the settled
// 100k pit kept 44,700 balls awake on average at 1, 46,000 at 2 and 48,400 at 4; pairs with a
// sleeper 0.024, 0.026 and 0.028 r deep on average (profiling/reports/sleeping.md).
inline constexpr float kSleepBelowDiameters = 2.0f;

// A region's level: the lowest height (SleepRegions::height) that something reaches in it: a
// sleeper at or above its region's wake level wakes, and an awake sphere sleeps only below its
// region's restless level less SleepRegions::below. kNoLevel: nothing reaches the region.
inline constexpr float kNoLevel = std::numeric_limits<float>::infinity();
using Levels = std::vector<float>;

struct SleepRegions {
  static constexpr float kMostTiles = 1024.0f;  // along each axis: at most a million regions

  int across[2] = {0, 2};    // the two axes the tiles cut (the third is gravity's)
  int down = 1;              // gravity's axis
  float up = 1.0f;           // +1 where gravity points to -down, else -1: height() grows upward
  float below = 0.0f;        // how far under a level a still sphere must lie to sleep (unit: m)
  float origin[2] = {};      // the pit's low corner along them (unit: m)
  float width = 1.0f;        // a tile's edge (unit: m)
  float per_width = 1.0f;    // 1 / width: tile() runs for every awake sphere a few times a step
  int count[2] = {1, 1};     // tiles along each axis

  // The regions of a pit under gravity g, for spheres up to max_radius.
  SleepRegions(const Pit& pit, const Vec3& g, float max_radius) {
    const Vec3 a = g.cwiseAbs();
    down = (a.x() > a.y() && a.x() >= a.z()) ? 0 : (a.z() > a.y() && a.z() > a.x()) ? 2 : 1;
    up = g[down] > 0.0f ? -1.0f : 1.0f;
    across[0] = down == 0 ? 1 : 0;
    across[1] = down == 2 ? 1 : 2;
    float extent[2];
    for (int k = 0; k < 2; ++k) {
      const bool vertical = across[k] == 1;
      origin[k] = vertical ? 0.0f : -pit.half_width;
      const float e = vertical ? pit.wall_height : 2.0f * pit.half_width;
      extent[k] = std::isfinite(e) && e > 0.0f ? e : 0.0f;  // the scene's checks refuse such a pit
    }
    // Regions wider than the spheres ask for where the pit would need more than kMostTiles
    // along an axis (a huge pit of small balls): every step allocates the regions' marks.
    width = std::max({kSleepRegionDiameters * 2.0f * max_radius, extent[0] / kMostTiles, extent[1] / kMostTiles, 1e-3f});
    per_width = 1.0f / width;
    below = kSleepBelowDiameters * 2.0f * max_radius;
    for (int k = 0; k < 2; ++k)
      count[k] = static_cast<int>(std::clamp(std::ceil(extent[k] * per_width), 1.0f, static_cast<float>(kMostTiles)));
  }

  std::size_t size() const { return static_cast<std::size_t>(count[0]) * count[1]; }

  // The tile index along axis k of coordinate c, clamped into the pit (NaN to 0).
  int tile(int k, float c) const {
    const float t = (c - origin[k]) * per_width;
    if (!(t >= 0.0f)) return 0;
    return t >= static_cast<float>(count[k] - 1) ? count[k] - 1 : static_cast<int>(t);
  }

  std::uint32_t of(const Vec3& p) const {
    return static_cast<std::uint32_t>(tile(0, p[across[0]]) * count[1] + tile(1, p[across[1]]));
  }

  // A position's height along -gravity: the column's other coordinate.
  float height(const Vec3& p) const { return up * p[down]; }

  // Lowers the level of every region the box [lo, hi] overlaps to the box's bottom.
  // Threads may lower the same region at once: the level ends as the least of their values
  // whatever their order, so the levels are the same for any thread count.
  void lower_box(const Vec3& lo, const Vec3& hi, Levels& levels) const {
    const float bottom = up > 0.0f ? lo[down] : -hi[down];
    const int a0 = tile(0, lo[across[0]]), a1 = tile(0, hi[across[0]]);
    const int b0 = tile(1, lo[across[1]]), b1 = tile(1, hi[across[1]]);
    for (int a = a0; a <= a1; ++a)
      for (int b = b0; b <= b1; ++b) lower(levels[static_cast<std::size_t>(a) * count[1] + b], bottom);
  }

  // Lowers one level to h. It is read first: most levels are low enough already, and a store
  // from every row would bounce the levels' cache lines between the cores (the sleep update of
  // an awake 100k pit took 2.8 ms a step instead of 0.3 with stores). NaN never lowers.
  static void lower(float& level, float h) {
    std::atomic_ref<float> l(level);
    float now = l.load(std::memory_order_relaxed);
    while (h < now && !l.compare_exchange_weak(now, h, std::memory_order_relaxed)) {
    }
  }

  static bool any_level(const Levels& levels) {
    return std::any_of(levels.begin(), levels.end(), [](float l) { return l < kNoLevel; });
  }

  // The wake level for a sleeper at p that was struck or pressed: a region's width under it, so
  // that the sleepers it rests on wake with it (the reach of a deep contact's hold, too).
  float wake_level_under(const Vec3& p) const { return height(p) - width; }

  // Whether an awake, still sphere at height h may sleep under its region's restless level.
  bool sleeps_under(float level, float h) const { return h < level - below; }

  // Sets out[r] for every region within `tiles` tiles of a region with marks set (out sized here).
  void dilate(const std::vector<std::uint8_t>& marks, int tiles, std::vector<std::uint8_t>& out) const {
    out.assign(size(), 0);
    for (int a = 0; a < count[0]; ++a)
      for (int b = 0; b < count[1]; ++b) {
        if (!marks[static_cast<std::size_t>(a) * count[1] + b]) continue;
        for (int i = std::max(a - tiles, 0); i <= std::min(a + tiles, count[0] - 1); ++i)
          std::memset(&out[static_cast<std::size_t>(i) * count[1] + std::max(b - tiles, 0)], 1,
                      static_cast<std::size_t>(std::min(b + tiles, count[1] - 1) - std::max(b - tiles, 0) + 1));
      }
  }

  // Sets one mark, read first as lower() is.
  static void mark(std::uint8_t& m) {
    std::atomic_ref<std::uint8_t> r(m);
    if (!r.load(std::memory_order_relaxed)) r.store(1, std::memory_order_relaxed);
  }
};

}  // namespace ballpit
