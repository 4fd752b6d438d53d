#include "systems/grid.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "engine/memory_use.h"
#include "engine/thread_share.h"
#include "engine/world.h"
#include "systems/sleep_regions.h"

namespace ballpit {

namespace {

// Fewest spheres worth a thread of their own: the rebuild and the reordering of the table
// stream memory, and a second thread gains little even at 100k (1.48 ms on 1 thread, 1.43 ms on
// 2) and loses at 10k (0.16 and 0.25 ms).
constexpr std::size_t kRowsPerThread = 32768;

// Min, max and largest radius: exact operations, so the parallel reduction is deterministic, and
// bounds of parts added together are the bounds of the whole.
GridBounds measure(std::span<const Vec3> p, std::span<const float> r) {
  GridBounds total;
  const std::int64_t n = static_cast<std::int64_t>(p.size());
#pragma omp parallel
  {
    GridBounds local;
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {
      if (!p[i].allFinite()) continue;  // the guard reports it; the grid clamps it to cell 0
      local.lo = local.lo.cwiseMin(p[i]);
      local.hi = local.hi.cwiseMax(p[i]);
      local.max_radius = std::max(local.max_radius, r[i]);
    }
#pragma omp critical
    total.add(local);
  }
  return total;
}

void choose_extent(SpatialGrid& g, GridBounds b, std::size_t n) {
  if (b.lo.x() > b.hi.x()) b.lo = b.hi = Vec3::Zero();  // no finite position
  g.max_radius = b.max_radius;
  g.slow_margin = kSlowMarginFraction * b.max_radius;
  g.cell_size = std::max(2.0f * (b.max_radius + g.slow_margin), 1e-6f);
  g.origin = b.lo;
  auto cells = [&](float extent) {
    double c = std::floor(static_cast<double>(extent) / g.cell_size) + 1.0;
    return static_cast<int>(std::clamp(c, 1.0, 1e6));
  };
  g.nx = cells(b.hi.x() - b.lo.x());
  g.ny = cells(b.hi.y() - b.lo.y());
  g.nz = cells(b.hi.z() - b.lo.z());
  // Cap the cell count at O(N). Height goes first: a pit is wide and shallow, and the spheres
  // that stretch the box upward are the few flying ones. Clamped spheres stay correct, only
  // slower to search.
  const std::size_t cap = std::max<std::size_t>(kCellsPerSphere * n, 64);
  std::size_t columns = static_cast<std::size_t>(g.nx) * g.nz;
  if (columns * g.ny > cap) g.ny = static_cast<int>(std::max<std::size_t>(1, cap / columns));
  while (static_cast<std::size_t>(g.nx) * g.nz * g.ny > cap) {
    if (g.nx >= g.nz) g.nx = std::max(1, g.nx / 2);
    else g.nz = std::max(1, g.nz / 2);
  }
}

// A stable parallel counting sort of rows [0, count) by cell key into slots [0, slots): fills
// cell_start[0, slots], and new_to_old and cell_of_row for those rows. Where `asleep` marks
// sleepers (the grid split), they take key cells + cell, after every awake row.
void sort_rows(SpatialGrid& g, std::span<const Vec3> p, std::span<const std::uint8_t> asleep, std::size_t count,
               std::size_t slots, GridScratch& s) {
  const std::size_t cells = g.cell_count();
  const int threads = omp_get_max_threads();
  s.keys.resize(count);
  s.histograms.assign(static_cast<std::size_t>(threads) * slots, 0);
  const std::int64_t rows = static_cast<std::int64_t>(count);
  std::vector<std::uint32_t> range_offset(static_cast<std::size_t>(threads), 0);

#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num();
    const int team = omp_get_num_threads();
    // The same contiguous chunk per thread in both passes keeps the scatter stable.
    const std::int64_t begin = rows * t / team, end = rows * (t + 1) / team;
    std::uint32_t* hist = s.histograms.data() + static_cast<std::size_t>(t) * slots;
    for (std::int64_t i = begin; i < end; ++i) {
      std::uint32_t k = g.key(g.clamp_x(p[i].x()), g.clamp_y(p[i].y()), g.clamp_z(p[i].z()));
      if (!asleep.empty() && asleep[i]) k += static_cast<std::uint32_t>(cells);
      s.keys[i] = k;
      ++hist[k];
    }
#pragma omp barrier
    // Prefix sum over (slot, thread): each thread totals its range of slots, one thread scans
    // the range totals, then each thread turns its range into scatter cursors.
    const std::size_t c0 = slots * t / team, c1 = slots * (t + 1) / team;
    std::uint32_t range_total = 0;
    for (std::size_t k = c0; k < c1; ++k)
      for (int u = 0; u < team; ++u) range_total += s.histograms[static_cast<std::size_t>(u) * slots + k];
    range_offset[t] = range_total;
#pragma omp barrier
#pragma omp single
    {
      std::uint32_t running = 0;
      for (int u = 0; u < team; ++u) {
        std::uint32_t total = range_offset[u];
        range_offset[u] = running;
        running += total;
      }
    }
    std::uint32_t offset = range_offset[t];
    for (std::size_t k = c0; k < c1; ++k) {
      g.cell_start[k] = offset;
      for (int u = 0; u < team; ++u) {
        std::uint32_t& h = s.histograms[static_cast<std::size_t>(u) * slots + k];
        std::uint32_t c = h;
        h = offset;  // histogram becomes the scatter cursor of thread u in slot k
        offset += c;
      }
    }
#pragma omp barrier
    for (std::int64_t i = begin; i < end; ++i) {
      std::uint32_t k = s.keys[i];
      std::uint32_t dst = hist[k]++;
      g.new_to_old[dst] = static_cast<std::uint32_t>(i);
      g.cell_of_row[dst] = k >= cells ? k - static_cast<std::uint32_t>(cells) : k;
    }
  }
  g.cell_start[slots] = static_cast<std::uint32_t>(count);
}

// The same sort of rows [0, count) for few rows among many cells, in one thread: a comparison
// sort of the rows, then one sweep over the cells for their starts, where the counting sort
// would clear, total and scan a histogram of every cell for each thread (a settled 1M pit's
// thousand awake rows among 500,000 cells).
void sort_few_rows(SpatialGrid& g, std::span<const Vec3> p, std::size_t count, std::size_t cells, GridScratch& s) {
  s.keys.resize(count);
  s.order.resize(count);
  for (std::size_t i = 0; i < count; ++i) s.keys[i] = g.key(g.clamp_x(p[i].x()), g.clamp_y(p[i].y()), g.clamp_z(p[i].z()));
  std::iota(s.order.begin(), s.order.end(), 0u);
  std::stable_sort(s.order.begin(), s.order.end(), [&](std::uint32_t a, std::uint32_t b) { return s.keys[a] < s.keys[b]; });
  std::size_t next = 0;
  for (std::size_t k = 0; k < cells; ++k) {
    g.cell_start[k] = static_cast<std::uint32_t>(next);
    for (; next < count && s.keys[s.order[next]] == k; ++next) {
      g.new_to_old[next] = s.order[next];
      g.cell_of_row[next] = static_cast<std::uint32_t>(k);
    }
  }
  g.cell_start[cells] = static_cast<std::uint32_t>(count);
}

struct Frame {
  float cell_size, slow_margin, max_radius;
  Vec3 origin;
  int nx, ny, nz;
  bool operator==(const Frame&) const = default;
};
Frame frame_of(const SpatialGrid& g) { return {g.cell_size, g.slow_margin, g.max_radius, g.origin, g.nx, g.ny, g.nz}; }

// Whether the last rebuild's sleepers are all still asleep in the rows it gave them, no sphere
// has fallen asleep since, and each sleeper is where it was then, as large, to the bit (a limb's
// guard or a user may move one or change its radius): then they are still sorted, and, if the
// frame stays the same, a rebuild keeps them where they are. A byte compare, where recomputing
// their cells took three divisions a row and most of the settled pour's rebuild.
bool sleepers_unchanged(const SpatialGrid& g, bool last_split, std::span<const Vec3> p, std::span<const float> r,
                        std::span<const std::uint8_t> asleep, const GridScratch& s) {
  const std::size_t n = p.size();
  if (!last_split || asleep.size() != n || g.cell_of_row.size() != n || g.cell_start.size() != 2 * g.cell_count() + 1 ||
      g.cell_start.back() != n)
    return false;
  const RowSpans spans = row_spans(asleep);
  const std::size_t awake = g.awake_rows();
  const std::size_t kept = s.sleeper_positions.size();
  if (spans.awake_end > awake || spans.asleep_begin != awake || kept != n - awake || s.sleeper_radii.size() != kept)
    return false;
  return std::memcmp(p.data() + awake, s.sleeper_positions.data(), kept * sizeof(Vec3)) == 0 &&
         std::memcmp(r.data() + awake, s.sleeper_radii.data(), kept * sizeof(float)) == 0;
}

}  // namespace

void build_grid(SpatialGrid& g, std::span<const Vec3> p, std::span<const float> r, GridScratch& s,
                std::span<const std::uint8_t> asleep) {
  const std::size_t n = p.size();
  const Frame last = frame_of(g);
  // A settled pit: the sleepers keep their rows, cells and index (the sleeper half of
  // cell_start), and only the awake rows are measured and sorted. The full sort would give the
  // same order (sorted rows stay in place in a stable sort), and the same frame: bounds add up.
  if (sleepers_unchanged(g, g.split, p, r, asleep, s)) {
    const std::size_t awake = g.awake_rows();
    if (!s.sleeper_bounds_measured) {  // once per full sort, and only if the sleepers then stay put
      s.sleeper_bounds = measure(s.sleeper_positions, s.sleeper_radii);
      s.sleeper_bounds_measured = true;
    }
    GridBounds b = measure(p.first(awake), r.first(awake));
    b.add(s.sleeper_bounds);
    choose_extent(g, b, n);
    if (frame_of(g) == last) {
      const std::size_t cells = g.cell_count();
      if (awake < cells / 8) sort_few_rows(g, p, awake, cells, s);
      else sort_rows(g, p, {}, awake, cells, s);
      // The sleepers' rows stay: the last rebuild that kept them left them so already.
      if (g.kept_since_sorted == 0)
        std::iota(g.new_to_old.begin() + static_cast<std::ptrdiff_t>(awake), g.new_to_old.end(), static_cast<std::uint32_t>(awake));
      ++g.kept_since_sorted;
      return;
    }
  } else {
    choose_extent(g, measure(p, r), n);
  }
  // Sleepers sort by key cells + cell, after every awake row.
  const std::size_t cells = g.cell_count();
  g.cell_of_row.resize(n);
  g.new_to_old.resize(n);
  static std::atomic<std::uint64_t> sorts{0};
  g.sleepers_sorted = ++sorts;
  g.kept_since_sorted = 0;
  g.split = asleep.size() == n && any_asleep(asleep);
  const std::size_t slots = g.split ? 2 * cells : cells;
  g.cell_start.assign(slots + 1, 0);
  sort_rows(g, p, g.split ? asleep : std::span<const std::uint8_t>{}, n, slots, s);
  s.sleeper_positions.clear();  // remember_sleepers keeps them once the rows are in this order
  s.sleeper_radii.clear();
}

void remember_sleepers(const SpatialGrid& g, std::span<const Vec3> p, std::span<const float> r, GridScratch& s) {
  if (!g.split || !s.sleeper_positions.empty()) return;
  const std::size_t awake = g.awake_rows();
  s.sleeper_positions.assign(p.begin() + static_cast<std::ptrdiff_t>(awake), p.end());
  s.sleeper_radii.assign(r.begin() + static_cast<std::ptrdiff_t>(awake), r.end());
  s.sleeper_bounds_measured = false;
}

std::vector<MemoryItem> GridSystem::held() const {
  return {{"histograms and keys", held_bytes(scratch_.histograms) + held_bytes(scratch_.keys) + held_bytes(scratch_.order)},
          {"sleepers' positions", held_bytes(scratch_.sleeper_positions) + held_bytes(scratch_.sleeper_radii)}};
}

Access GridSystem::access() const {
  Access a;
  a.reads = ColumnSet::all_sphere_columns();
  a.writes = ColumnSet::all_sphere_columns();
  a.writes.add(ColumnId::Grid);
  return a;
}

void GridSystem::run(World& world) {
  const TeamSize team(team_for(world.spheres.size(), kRowsPerThread));
  // A pit asleep whole has not moved since it fell asleep: its rows keep their order, and
  // nothing searches the grid this step (systems/sleeping.h). The identity permutation tells
  // the narrowphase and the solver that last step's rows are this step's.
  if (all_asleep(world.spheres.asleep())) {
    std::vector<std::uint32_t>& order = world.grid.new_to_old;
    if (order.size() != world.spheres.size() || !world.grid.kept_order) {
      order.resize(world.spheres.size());
      std::iota(order.begin(), order.end(), 0u);
    }
    world.grid.kept_order = true;
    return;
  }
  world.grid.kept_order = false;
  build_grid(world.grid, world.spheres.position(), world.spheres.radius(), scratch_, world.spheres.asleep());
  // A rebuild that kept the sleepers moves only the awake rows.
  const SpatialGrid& g = world.grid;
  world.spheres.permute(g.new_to_old, g.kept_since_sorted > 0 ? g.awake_rows() : g.new_to_old.size());
  remember_sleepers(g, world.spheres.position(), world.spheres.radius(), scratch_);
}

}  // namespace ballpit
