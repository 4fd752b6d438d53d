// How the search is laid out (narrowphase.h says what it finds). Slabs run in parallel; within
// one, cells are visited in key order, so generator rows come in row order and every list comes
// out exactly as a row-by-row search would write it. A slow sphere tests the five row ranges of
// its forward neighbourhood four rows at a time, on columns of floats copied once per step,
// gathers the rows that pass, then makes their contacts. A fast sphere searches a wider box
// all around with the same test, and keeps the pairs it owns; the naive reference mode tests
// every sphere against every row one candidate at a time.
#include "systems/narrowphase.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <string>

#include "engine/error.h"
#include "engine/list_capacity.h"
#include "engine/memory_use.h"
#include "engine/thread_share.h"
#include "engine/world.h"
#include "systems/sleep_regions.h"

// The candidate and plane tests run four rows at a time in SSE2 where the target has it (every
// x86-64), one at a time otherwise or with BALLPIT_NARROWPHASE_SCALAR; both give the same bits.
#if defined(__SSE2__) && !defined(BALLPIT_NARROWPHASE_SCALAR)
#include <immintrin.h>
#define BALLPIT_NARROWPHASE_SSE 1
#endif

namespace ballpit {

namespace {

// Fewest spheres worth a thread of their own. Threads spinning: a settled 1k pile found its
// contacts in 0.07 ms on 1 thread and 0.11 ms on 2; one of 3k in 0.36 and 0.25 ms. Waiting
// passively (the pour, settled): 0.30 / 0.34 ms at 3k, 0.51 / 0.43 at 5k.
constexpr PerThread kRowsPerThread{.spinning = 1024, .passive = 2048};

// NarrowphaseScratch::flags bits.
constexpr std::uint32_t kFastRow = 1;    // margin beyond what a one-cell search covers
constexpr std::uint32_t kAsleepRow = 2;
constexpr std::uint32_t kAwakeRow = 4;   // so that a search can skip every awake partner
constexpr std::uint32_t kSleptRow = 8;   // slept when the cache was written: its entries are kept by entity

// Slow spheres test their candidates this many rows at a time (one SSE register of floats).
constexpr std::uint32_t kLanes = 4;

// How far ahead of the list's end the slots of new contacts are prefetched (8 x 40 bytes: five
// cache lines, about two slow spheres' contacts).
constexpr std::size_t kPrefetchContacts = 8;

// Rows [begin, end) of the sphere table.
struct RowRange {
  std::uint32_t begin = 0, end = 0;
};

// The scratch columns as plain pointers. Held in locals, they stay in registers through the
// candidate loop; read through the vectors, they are reloaded after every contact stored
// (the compiler cannot tell a vector's end pointer from theirs).
struct Columns {
  const float* x;
  const float* y;
  const float* z;
  const float* radius;
  const float* margin;
  const std::uint32_t* flags;
};

// Left-packing of kLanes test results: row m lists the lanes whose bits are set in m, in order
// (then filler), and kPassedCount[m] counts them.
constexpr std::uint32_t kPassedLanes[16][kLanes] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0}, {1, 2, 0, 0}, {0, 1, 2, 0},
    {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0}, {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
constexpr std::uint32_t kPassedCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// The pit's planes, looked up once per step and laid out as lanes (plane p in lane p of two
// groups of kLanes), so that a row tests four planes per instruction. near() is the test
// n.dot(x) - offset - r < margin, in Eigen's order (n0 x0 + (n1 x1 + n2 x2)), lane by lane.
struct PitPlanes {
  static constexpr int kGroups = 2;
  static_assert(Pit::kMaxPlanes <= kGroups * kLanes);
  alignas(16) float nx[kGroups * kLanes], ny[kGroups * kLanes], nz[kGroups * kLanes], offset[kGroups * kLanes];
  unsigned planes;  // mask of the pit's planes

  explicit PitPlanes(const Pit& pit) : nx(), ny(), nz(), offset(), planes((1u << pit.plane_count()) - 1u) {
    for (int p = 0; p < pit.plane_count(); ++p) {
      const Vec3 n = pit.plane_normal(p);
      nx[p] = n.x();
      ny[p] = n.y();
      nz[p] = n.z();
      offset[p] = pit.plane_offset(p);
    }
  }

  // Bit p set: the row's gap to plane p is below its margin (whether the plane applies there
  // is the caller's question).
  unsigned near(const Vec3& x, float r, float m) const {
    unsigned bits = 0;
#if BALLPIT_NARROWPHASE_SSE
    const __m128 px = _mm_set1_ps(x.x()), py = _mm_set1_ps(x.y()), pz = _mm_set1_ps(x.z());
    const __m128 pr = _mm_set1_ps(r), pm = _mm_set1_ps(m);
    for (int g = 0; g < kGroups; ++g) {
      const int l = g * static_cast<int>(kLanes);
      const __m128 dot = _mm_add_ps(_mm_mul_ps(_mm_load_ps(nx + l), px),
                                    _mm_add_ps(_mm_mul_ps(_mm_load_ps(ny + l), py), _mm_mul_ps(_mm_load_ps(nz + l), pz)));
      const __m128 gap = _mm_sub_ps(_mm_sub_ps(dot, _mm_load_ps(offset + l)), pr);
      bits |= static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(gap, pm))) << l;
    }
#else
    for (int p = 0; p < kGroups * static_cast<int>(kLanes); ++p)
      bits |= unsigned(Vec3(nx[p], ny[p], nz[p]).dot(x) - offset[p] - r < m) << p;
#endif
    return bits & planes;
  }
};

// The box a joint collider's segment [a, b] spans, grown by the collider's radius and margin:
// a sphere centre farther out along any axis than its own radius and margin cannot be within
// reach of the segment. misses() only says no where the exact test would (the slack covers the
// rounding of both), and a NaN centre is never missed, so the filter changes no contact. A
// default box is empty; add() grows it around another.
struct ColliderBox {
  Vec3 lo = Vec3::Constant(1e30f), hi = Vec3::Constant(-1e30f);

  ColliderBox() = default;
  ColliderBox(const Vec3& a, const Vec3& b, float grow) {
    const float slack = 1e-3f + 1e-5f * std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
    lo = a.cwiseMin(b) - Vec3::Constant(grow + slack);
    hi = a.cwiseMax(b) + Vec3::Constant(grow + slack);
  }

  void add(const ColliderBox& other) {
    lo = lo.cwiseMin(other.lo);
    hi = hi.cwiseMax(other.hi);
  }

  bool misses(const Vec3& x, float grow) const {
    return (x.array() < lo.array() - grow).any() || (x.array() > hi.array() + grow).any();
  }
};

struct SlabSearch {
  const SpatialGrid& grid;
  std::span<const Vec3> x;
  std::span<const float> r;
  std::span<const std::uint16_t> material;
  std::span<const std::uint32_t> entity;
  const NarrowphaseScratch& scratch;
  const std::vector<Material>& pair_material;  // materials x materials, combined
  std::size_t material_count;
  const ContactSet& previous;                  // warm-start cache of the last step
  std::span<const std::uint32_t> new_to_old;
  std::uint8_t* piled;                         // ContactSet::piled of this step

  // A pair that carried load marks both its rows as piled. The partner may lie in the next slab,
  // whose rows another thread marks too, so the mark is an atomic store (on x86 a plain one).
  void mark_piled(const Contact& c) const {
    if (!c.loaded_last_step()) return;
    std::atomic_ref<std::uint8_t>(piled[c.a]).store(1, std::memory_order_relaxed);
    std::atomic_ref<std::uint8_t>(piled[c.b]).store(1, std::memory_order_relaxed);
  }

  // Is row j in the slab or the next one? Rows are sorted by cell key and a slab is a key range,
  // so it is a row range (one among the awake rows, one among the sleepers): two lookups
  // instead of a division of j's key per pair.
  bool local(std::uint32_t j, int slab) const {
    const int next = std::min(slab + 2, grid.nx);
    if (j < grid.awake_rows()) return j >= grid.slab_row_begin(slab) && j < grid.slab_row_begin(next);
    return j >= grid.slab_sleeper_begin(slab) && j < grid.slab_sleeper_begin(next);
  }

  // Last step's entries of the sphere at row i (engine/contact_set.h: a sleeper's are kept apart,
  // which its flag says without a read of the cache's own).
  ContactSet::RowEntries cached(std::uint32_t i) const {
    if (new_to_old.empty()) return {};
    return (scratch.flags[i] & kSleptRow) ? previous.kept_entries(entity[i]) : previous.fresh_entries(new_to_old[i]);
  }

  const WarmStartEntry* warm(std::uint32_t i, std::uint32_t partner) const { return cached(i).find(partner); }

  // `reversed`: the cached contact had a and b the other way round (row order decides which
  // sphere generates a pair, and rows are re-sorted every step), so its friction impulse, which
  // acts on a as -F and on b as +F, changes sign. The normal impulse is along a -> b either way.
  // A pair without an entry starts from zero impulses: it reads them from kNoEntry rather than
  // branching on whether it has one, which a third of all pairs do not, at no predictable place.
  static Contact make(std::uint32_t a, std::uint32_t b, const Material& m, const WarmStartEntry* w,
                      bool reversed = false) {
    static const WarmStartEntry kNoEntry{0, 0.0f, Vec3::Zero()};
    const WarmStartEntry& e = w ? *w : kNoEntry;
    const Vec3 friction = reversed ? Vec3(-e.friction_impulse) : e.friction_impulse;
    return {a, b, e.normal_impulse, friction, m.friction, m.restitution};
  }

  // What the contacts of generator row i share, looked up once for all of them.
  struct Generator {
    std::uint32_t i;
    std::uint32_t entity;
    std::uint32_t entity_bit;              // partner_bit(entity)
    const Material* materials;             // i's row of pair_material
    ContactSet::RowEntries warm;           // i's entries of last step
  };

  Generator generator(std::uint32_t i) const {
    return {i, entity[i], partner_bit(entity[i]), &pair_material[material[i] * material_count], cached(i)};
  }

  // The partner's own entries are searched only if its summary allows: most pairs that i did
  // not cache were not cached at all (they carried no impulse), and the partner's entries lie
  // ahead in the cache, where reading them costs a miss.
  Contact pair(const Generator& g, std::uint32_t j) const {
    const WarmStartEntry* w = g.warm.find(entity[j]);
    bool reversed = false;
    if ((scratch.cached[j] & g.entity_bit) && !w) reversed = (w = cached(j).find(g.entity)) != nullptr;
    return make(g.i, j, g.materials[material[j]], w, reversed);
  }

  void add_pair(std::uint32_t i, std::uint32_t j, int slab, SlabContacts& out) const {
    auto& list = local(j, slab) ? out.pairs : out.serial;
    list.push_back(pair(generator(i), j));
    mark_piled(list.back());
  }

  bool fast(std::uint32_t i) const { return scratch.flags[i] & kFastRow; }

  bool touching_soon(std::uint32_t i, std::uint32_t j) const {
    if (scratch.flags[i] & scratch.flags[j] & kAsleepRow) return false;
    float reach = r[i] + r[j] + scratch.margin[i] + scratch.margin[j];
    return (x[j] - x[i]).squaredNorm() < reach * reach;
  }

  bool asleep(std::uint32_t j) const { return scratch.flags[j] & kAsleepRow; }

  // Does the slow awake sphere i own the pair with j? Fast spheres record their own pairs, and
  // sleepers none.
  bool slow_owns(std::uint32_t i, std::uint32_t j) const { return (j > i || asleep(j)) && !fast(j); }

  // A fast sphere owns pairs with slow spheres (sleepers are slow), and with fast ones of
  // smaller margin (ties by row), so exactly one side records each pair.
  bool fast_owns(std::uint32_t i, std::uint32_t j) const {
    if (i == j) return false;
    if (!fast(j)) return true;
    float mi = scratch.margin[i], mj = scratch.margin[j];
    return mj < mi || (mj == mi && j > i);
  }

  // One candidate at a time: the reference mode.
  void scan_rows(std::uint32_t i, RowRange rows, int slab, SlabContacts& out) const {
    const bool fast_i = fast(i);
    for (std::uint32_t j = rows.begin; j < rows.end; ++j) {
      if (!(fast_i ? fast_owns(i, j) : slow_owns(i, j))) continue;
      if (touching_soon(i, j)) add_pair(i, j, slab, out);
    }
  }

  // The flags that rule out a partner of awake row i before the distance test: for a slow
  // sphere a fast partner, which records the pair itself (fast_owns).
  std::uint32_t skipped_partners(std::uint32_t i) const { return fast(i) ? 0u : kFastRow; }

  // Sphere i's side of the candidate test, in every lane, passing no row whose flags meet `skip`.
#if BALLPIT_NARROWPHASE_SSE
  struct Probe {
    __m128 x, y, z, r, m;
    __m128i skip;  // skipped_partners(i)
  };
  Probe probe(const Columns& c, std::uint32_t i, std::uint32_t skip) const {
    return {_mm_set1_ps(c.x[i]),      _mm_set1_ps(c.y[i]),      _mm_set1_ps(c.z[i]),
            _mm_set1_ps(c.radius[i]), _mm_set1_ps(c.margin[i]), _mm_set1_epi32(static_cast<int>(skip))};
  }

  // Bit k set: row j + k is not skipped and touches sphere i soon. The arithmetic is
  // touching_soon's, lane by lane and in its order (Eigen sums a squared norm of three as
  // x + (y + z); no FMA), so the same pairs pass to the last bit.
  static unsigned hits(const Columns& c, const Probe& p, std::uint32_t j) {
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(c.x + j), p.x);
    const __m128 dy = _mm_sub_ps(_mm_loadu_ps(c.y + j), p.y);
    const __m128 dz = _mm_sub_ps(_mm_loadu_ps(c.z + j), p.z);
    const __m128 d2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_add_ps(_mm_mul_ps(dy, dy), _mm_mul_ps(dz, dz)));
    const __m128 reach =
        _mm_add_ps(_mm_add_ps(_mm_add_ps(p.r, _mm_loadu_ps(c.radius + j)), p.m), _mm_loadu_ps(c.margin + j));
    const __m128 near = _mm_cmplt_ps(d2, _mm_mul_ps(reach, reach));
    const __m128i skipped = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c.flags + j)), p.skip);
    const __m128 owned = _mm_castsi128_ps(_mm_cmpeq_epi32(skipped, _mm_setzero_si128()));
    return static_cast<unsigned>(_mm_movemask_ps(_mm_and_ps(near, owned)));
  }
#else
  struct Probe {
    std::uint32_t i, skip;
  };
  Probe probe(const Columns&, std::uint32_t i, std::uint32_t skip) const { return {i, skip}; }
  unsigned hits(const Columns&, const Probe& p, std::uint32_t j) const {
    unsigned passed = 0;
    for (std::uint32_t k = 0; k < kLanes && j + k < x.size(); ++k)
      passed |= unsigned(!(scratch.flags[j + k] & p.skip) && touching_soon(p.i, j + k)) << k;
    return passed;
  }
#endif

  // Writes the rows of `rows` that pass to `out`, in order, and returns the end of what it
  // wrote. About one candidate in seven passes, at no predictable place, so nothing here
  // branches on the test: every lane is written, and the end moves past the passing ones only.
  // A row's slot is thus written no later than its own turn. Lanes past the range's end read
  // the scratch padding and are masked off.
  std::uint32_t* gather(const Columns& c, const Probe& p, RowRange rows, std::uint32_t* out) const {
    for (std::uint32_t j = rows.begin; j < rows.end; j += kLanes) {
      const std::uint32_t lanes = std::min(rows.end - j, kLanes);
      const unsigned passed = hits(c, p, j) & (0xFu >> (kLanes - lanes));
      for (std::uint32_t k = 0; k < kLanes; ++k) out[k] = j + kPassedLanes[passed][k];
      out += kPassedCount[passed];
    }
    return out;
  }

  // The contacts of the rows [passed, end) that passed the slow sphere's test. Its partners lie
  // in its slab or the next, so all are local. The list keeps its capacity from step to step,
  // so the slots about to be written are last step's memory, long gone from the near caches:
  // they are asked for a few contacts ahead, never past the capacity (the address would be
  // undefined there, and null before the first step).
  void emit(const Generator& g, const std::uint32_t* passed, const std::uint32_t* end, SlabContacts& out) const {
    for (; passed < end; ++passed) {
      const std::size_t ahead = std::min(out.pairs.size() + kPrefetchContacts, out.pairs.capacity());
      __builtin_prefetch(out.pairs.data() + ahead, 1);
      out.pairs.push_back(pair(g, *passed));
      mark_piled(out.pairs.back());
    }
  }

  // Cells (cx, y0..y1, cz), y clipped to the grid: consecutive keys, so one row range, in the
  // order the cells one by one would give them. Empty outside the grid. Awake rows, or with
  // `sleeping` the sleepers' (none unless the grid is split).
  RowRange column(int cx, int y0, int y1, int cz, bool sleeping = false) const {
    if (cx < 0 || cx >= grid.nx || cz < 0 || cz >= grid.nz) return {};
    if (sleeping && !grid.split) return {};
    y0 = std::max(y0, 0);
    y1 = std::min(y1, grid.ny - 1);
    if (y0 > y1) return {};
    const std::size_t first = sleeping ? grid.cell_count() : 0;
    return {grid.cell_start[first + grid.key(cx, y0, cz)], grid.cell_start[first + grid.key(cx, y1, cz) + 1]};
  }

  // The awake spheres of cell (cx, cy, cz) against the forward half of its 27-cell
  // neighbourhood: cells with a larger key, plus the own cell (partners of larger row only).
  // Keys grow with y, then z, then x, so rows do too, and the cells of one (x, z) column that
  // differ in y are one range of rows: five ranges, in row order, the same for every slow
  // sphere of the cell. Its pairs with the sleepers of the whole neighbourhood come first
  // (sleeping_pairs): a sleeper is fixed, a support like the floor, and solved before the awake
  // pairs its support passes up through, as planes are (systems/solver.cpp). After them, a
  // region woken in a sleeping pile sagged more in its first step (fastest ball 0.063 m/s
  // against 0.048, tests/test_sleeping.cpp: ARegionWokenByAMover...). The rows
  // that pass are gathered in `passed` (room for every candidate of the cell, plus a kLanes - 1
  // write past the last), and their contacts made after the whole search, in one loop: both
  // loops then run without branches on the test.
  void cell_pairs(const Columns& c, int cx, int cy, int cz, RowRange cell, int slab, std::vector<std::uint32_t>& passed,
                  SlabContacts& out) const {
    const RowRange forward[5] = {column(cx, cy, cy + 1, cz), column(cx, cy - 1, cy + 1, cz + 1),
                                 column(cx + 1, cy - 1, cy + 1, cz - 1), column(cx + 1, cy - 1, cy + 1, cz),
                                 column(cx + 1, cy - 1, cy + 1, cz + 1)};
    const SleepingNeighbours sleeping = sleeping_neighbours(cx, cy, cz);
    std::size_t candidates = std::max<std::size_t>(forward[0].end - cell.begin, sleeping.candidates);
    for (int k = 1; k < 5; ++k) candidates += forward[k].end - forward[k].begin;
    if (passed.size() < candidates + kLanes) passed.resize(candidates + kLanes);
    for (std::uint32_t i = cell.begin; i < cell.end; ++i) {
      if (fast(i)) {
        wide_pairs(c, i, cx, cy, cz, slab, passed, out);
        continue;
      }
      if (sleeping.candidates) sleeping_pairs(c, i, sleeping, slab, passed, out);
      const Probe p = probe(c, i, skipped_partners(i));
      // The own cell's rows up to i belong to pairs that earlier rows own.
      std::uint32_t* end = gather(c, p, {i + 1, forward[0].end}, passed.data());
      for (int k = 1; k < 5; ++k) end = gather(c, p, forward[k], end);
      emit(generator(i), passed.data(), end, out);
    }
  }

  // The sleepers of cell (cx, cy, cz)'s whole neighbourhood: nine (x, z) columns of three
  // cells, in row order; the same for every sphere of the cell, and none at all for most cells
  // of an awake crowd.
  struct SleepingNeighbours {
    RowRange around[9];
    std::size_t candidates = 0;
  };
  SleepingNeighbours sleeping_neighbours(int cx, int cy, int cz) const {
    SleepingNeighbours s;
    if (!grid.split) return s;
    for (int dx = -1, k = 0; dx <= 1; ++dx)
      for (int dz = -1; dz <= 1; ++dz, ++k) {
        s.around[k] = column(cx + dx, cy - 1, cy + 1, cz + dz, true);
        s.candidates += s.around[k].end - s.around[k].begin;
      }
    return s;
  }

  // A sleeper owns no pair, so the slow awake sphere i owns its pairs with the sleepers of its
  // neighbourhood. Those lie in this slab, the next or the one before; a pair with the one
  // before goes to the serial list (add_pair).
  void sleeping_pairs(const Columns& c, std::uint32_t i, const SleepingNeighbours& sleeping, int slab,
                      std::vector<std::uint32_t>& passed, SlabContacts& out) const {
    const Probe p = probe(c, i, kAwakeRow);
    std::uint32_t* end = passed.data();
    for (const RowRange& rows : sleeping.around) end = gather(c, p, rows, end);
    for (const std::uint32_t* j = passed.data(); j < end; ++j) add_pair(i, *j, slab, out);
  }

  // A fast sphere searches every cell its reach may touch, all around, with the slow spheres'
  // test, which passes it fast partners too, and records the pairs it owns. Its partners may lie
  // in any slab. (One candidate at a time, a 100k pit with a running character spent half its
  // search on the few thousand balls the character flung.)
  void wide_pairs(const Columns& c, std::uint32_t i, int cx, int cy, int cz, int slab,
                  std::vector<std::uint32_t>& passed, SlabContacts& out) const {
    float reach = r[i] + grid.max_radius + 2.0f * scratch.margin[i];
    // A margin can be huge or infinite (a state of 1e19 m/s, a step of 1e30 s): clamp in float,
    // before converting, since no search needs more cells than the grid has along an axis.
    const float cells = std::ceil(reach / grid.cell_size);
    const int most = std::max(grid.nx, std::max(grid.ny, grid.nz));
    const int span = cells < static_cast<float>(most) ? static_cast<int>(cells) : most;  // NaN too
    // Searching past the grid is pointless: clamped cells hold everything beyond it.
    int x0 = std::max(cx - span, 0), x1 = std::min(cx + span, grid.nx - 1);
    int z0 = std::max(cz - span, 0), z1 = std::min(cz + span, grid.nz - 1);
    int y0 = std::max(cy - span, 0), y1 = std::min(cy + span, grid.ny - 1);
    const Probe p = probe(c, i, skipped_partners(i));
    for (const bool sleeping : {false, true})
      for (int ax = x0; ax <= x1; ++ax)
        for (int az = z0; az <= z1; ++az) {
          const RowRange rows = column(ax, y0, y1, az, sleeping);
          if (passed.size() < rows.end - rows.begin + kLanes) passed.resize(rows.end - rows.begin + kLanes);
          const std::uint32_t* end = gather(c, p, rows, passed.data());
          for (const std::uint32_t* j = passed.data(); j < end; ++j)
            if (fast_owns(i, *j)) add_pair(i, *j, slab, out);
        }
  }

  // The slab's awake cells in key order, so rows in row order.
  void grid_pairs(int slab, SlabContacts& out) const {
    const Columns c{scratch.x.data(),      scratch.y.data(),      scratch.z.data(),
                    scratch.radius.data(), scratch.margin.data(), scratch.flags.data()};
    std::vector<std::uint32_t> passed;
    for (int cz = 0; cz < grid.nz; ++cz)
      for (int cy = 0; cy < grid.ny; ++cy) {
        const std::uint32_t k = grid.key(slab, cy, cz);
        const RowRange cell{grid.cell_start[k], grid.cell_start[k + 1]};
        if (cell.begin < cell.end) cell_pairs(c, slab, cy, cz, cell, slab, passed, out);
      }
  }

  void naive_pairs(std::uint32_t i, int slab, SlabContacts& out) const {
    scan_rows(i, {0, static_cast<std::uint32_t>(x.size())}, slab, out);
  }
};

}  // namespace

std::vector<MemoryItem> NarrowphaseSystem::held() const {
  const NarrowphaseScratch& s = scratch_;
  std::size_t rows = held_bytes(s.flags);
  for (const auto* column : {&s.x, &s.y, &s.z, &s.radius, &s.margin}) rows += held_bytes(*column);
  return {{"row columns", rows},
          {"warm-start summaries", held_bytes(s.cached_by_old_row) + held_bytes(s.cached)}};
}

Access NarrowphaseSystem::access() const {
  Access a;
  a.reads = {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereRadius,
             ColumnId::SphereMaterial, ColumnId::SphereSleep,    ColumnId::SphereRows,
             ColumnId::Grid,           ColumnId::Colliders,      ColumnId::Gravity};
  a.writes = {ColumnId::Contacts};
  return a;
}

void find_contacts(World& world, NarrowphaseScratch& scratch) {
  const TeamSize team(team_for(world.spheres.size(), kRowsPerThread));
  const SphereTable& spheres = world.spheres;
  const SpatialGrid& grid = world.grid;
  const std::size_t n = spheres.size();
  const float dt = world.step();
  const float g = world.gravity().norm();
  auto x = spheres.position();
  auto v = spheres.velocity();
  auto r = spheres.radius();
  auto asleep = spheres.asleep();

  // The padding rows keep the last load of kLanes in bounds; their lanes are masked off.
  const std::size_t padded = n + kLanes - 1;
  for (auto* column : {&scratch.x, &scratch.y, &scratch.z, &scratch.radius, &scratch.margin}) column->resize(padded);
  scratch.flags.resize(padded);

  const std::size_t mc = world.materials.size();
  std::vector<Material> pair_material(mc * mc);
  for (std::size_t a = 0; a < mc; ++a)
    for (std::size_t b = 0; b < mc; ++b) pair_material[a * mc + b] = combine(world.materials[a], world.materials[b]);
  // Planes and joint colliders are made of the pit's material.
  std::vector<Material> pit_material(mc);
  for (std::size_t a = 0; a < mc; ++a) pit_material[a] = combine(world.materials[a], world.pit.material);

  // Joint colliders: the box around all of them filters spheres cheaply, and each collider's own
  // box filters the spheres inside that; only the spheres in a collider's box test its segment.
  const ColliderTable& colliders = world.colliders;
  auto ca = colliders.a();
  auto cb = colliders.b();
  auto cr = colliders.radius();
  std::vector<float> collider_margin(colliders.size());
  std::vector<ColliderBox> collider_box(colliders.size());
  ColliderBox all_colliders;
  for (std::size_t c = 0; c < colliders.size(); ++c) {
    collider_margin[c] = colliders.speed(c) * dt;
    collider_box[c] = ColliderBox(ca[c], cb[c], cr[c] + collider_margin[c]);
    all_colliders.add(collider_box[c]);
  }

  // A world with joint colliders runs whole steps, not passes (engine/step_passes.h), so its
  // margins must cover a whole step's motion: the cap would let a flung ball through.
  const bool margins_capped = colliders.size() == 0;

  const Pit& pit = world.pit;
  const PitPlanes pit_planes(pit);
  const float static_extra = static_margin_extra(dt, g);

  ContactSet& contacts = world.contacts;
  const int slabs = grid.nx;
  // Last step's cache stays valid while this step's lists are rebuilt: the solver writes a
  // fresh cache at its end.
  if (contacts.slabs.size() != static_cast<std::size_t>(slabs)) contacts.slabs.resize(slabs);
  contacts.piled.assign(n, 0);
  if (all_asleep(asleep)) {  // no sphere moves: nothing to find (systems/sleeping.h)
    for (SlabContacts& slab : contacts.slabs) {
      slab.pairs.clear();
      slab.statics.clear();
      slab.serial.clear();
    }
    return;
  }
  const RowSpans spans = row_spans(asleep);
  if (n > 0 && (grid.cell_start.size() < grid.cell_count() + 1 || grid.new_to_old.size() != n ||
      spans.awake_end != grid.awake_rows() || spans.asleep_begin != grid.awake_rows()))
    throw Error("narrowphase: the grid was built for other rows or another sleep state than the sphere table's (" +
                std::to_string(n) + " rows, " + std::to_string(spans.awake_end) +
                " awake first); the grid must run after the wake system and before the narrowphase");
  SlabSearch search{grid,
                    x,
                    r,
                    spheres.material(),
                    spheres.entity_index(),
                    scratch,
                    pair_material,
                    mc,
                    contacts,
                    grid.new_to_old,
                    contacts.piled.data()};
  const bool naive = world.solver.narrowphase == NarrowphaseMode::Naive;

  // Summaries of last step's cache entries, made in the cache's own (old row) order so the
  // entries are read straight through, then gathered into this step's rows; then the search.
  // One team does all three, with a barrier after each of the first two (each parallel region
  // wakes the team, which costs tens of microseconds where threads wait passively).
  const ContactSet& previous = world.contacts;
  const std::int64_t old_rows = previous.warm_begin.empty() ? 0 : static_cast<std::int64_t>(previous.warm_begin.size() - 1);
  scratch.cached_by_old_row.resize(static_cast<std::size_t>(old_rows));
  scratch.cached.resize(n);
  std::span<const std::uint32_t> new_to_old = grid.new_to_old;
  // The sleepers' row columns stay as the last step made them when it made them after the
  // rebuild that last sorted the sleepers: their rows, positions, margins and flags, and the
  // cache's view of them (slept rows, their kept summaries), are as they were then (a sleep
  // change or a sleeper moved sorts them again). A settled pit's pass then costs its awake rows.
  // (Made at the sorting rebuild itself, the slept rows were the cache's before it: not yet.)
  const bool sleepers_kept = grid.split && grid.kept_since_sorted > 0 && scratch.made_kept &&
                             scratch.sleepers_sorted == grid.sleepers_sorted && scratch.made_rows == n;
  const std::int64_t count = static_cast<std::int64_t>(sleepers_kept ? grid.awake_rows() : n);
  if (!sleepers_kept) {
    scratch.sleepers_sorted = grid.sleepers_sorted;
    scratch.made_kept = grid.kept_since_sorted > 0;
    scratch.made_rows = n;
  }
  auto entity = spheres.entity_index();
  // A row that slept has its entries, and their summary, kept by entity (engine/contact_set.h):
  // the old-row pass skips it, and the gather looks the summary up.
  auto slept = [&](std::uint32_t old_row) { return old_row < previous.row_slept.size() && previous.row_slept[old_row]; };
  auto kept_summary = [&](std::uint32_t e) { return e < previous.kept.partners.size() ? previous.kept.partners[e] : 0u; };
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (std::int64_t o = 0; o < old_rows; ++o) {
      if (slept(static_cast<std::uint32_t>(o))) continue;  // its summary is kept_summary's
      std::uint32_t summary = 0;
      for (std::uint32_t k = previous.warm_begin[o]; k < previous.warm_begin[o + 1]; ++k)
        summary |= partner_bit(previous.warm[k].partner);
      scratch.cached_by_old_row[o] = summary;
    }  // and the loop's barrier

#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < count; ++i) {
      float m = asleep[i]          ? kMinMarginFraction * r[i]
                : margins_capped ? capped_pair_margin(v[i].norm(), dt, g, r[i])
                                 : pair_margin(v[i].norm(), dt, g, r[i]);
      scratch.x[i] = x[i].x();
      scratch.y[i] = x[i].y();
      scratch.z[i] = x[i].z();
      scratch.radius[i] = r[i];
      scratch.margin[i] = m;
      const bool has_old_row = static_cast<std::size_t>(i) < new_to_old.size() && new_to_old[i] < old_rows;
      const bool kept = has_old_row && slept(new_to_old[i]);
      scratch.flags[i] = (m > grid.slow_margin ? kFastRow : 0u) | (asleep[i] ? kAsleepRow : kAwakeRow) | (kept ? kSleptRow : 0u);
      scratch.cached[i] = !has_old_row ? 0u : kept ? kept_summary(entity[i]) : scratch.cached_by_old_row[new_to_old[i]];
    }  // and the loop's barrier

    // Contiguous runs of slabs of about equal rows per thread (engine/thread_share.h): each
    // thread writes the lists of the stretch of the pit whose contacts it will pack and solve.
    const auto [first, last] = thread_share(slabs, [&](int s) { return std::size_t{grid.slab_row_begin(s)}; });
    for (int s = first; s < last; ++s) {
      SlabContacts& out = contacts.slabs[s];
      for (std::vector<Contact>* list : {&out.pairs, &out.statics, &out.serial}) {
        release_excess_capacity(*list, list->size());  // the slab's peak, once it has passed
        list->clear();
      }
      const std::uint32_t begin = grid.slab_row_begin(s), end = grid.slab_row_begin(s + 1);
      if (naive) {
        for (std::uint32_t i = begin; i < end; ++i) search.naive_pairs(i, s, out);
      } else {
        search.grid_pairs(s, out);
      }
      // The slab's awake rows. A sleeper is held where it fell asleep: its floor and walls are
      // not solved, and keep their impulses in the cache for when it wakes (systems/solver.cpp);
      // a collider that moves at it wakes it first (systems/sleeping.h).
      for (std::uint32_t i = begin; i < end; ++i) {
        // Copies: the lists' stores would otherwise force a reload per plane.
        const Vec3 xi = x[i];
        // The row's pair margin, made above from the same speed (speculative_margin).
        const float ri = r[i], m = scratch.margin[i] + static_extra;
        const Material& mat = pit_material[search.material[i]];
        for (unsigned near = pit_planes.near(xi, ri, m); near; near &= near - 1) {
          const int p = std::countr_zero(near);
          if (!pit.plane_applies(p, xi)) continue;
          std::uint32_t id = kPlaneTag | static_cast<std::uint32_t>(p);
          out.statics.push_back(search.make(i, id, mat, search.warm(i, id)));
        }
        if (colliders.size() == 0) continue;
        // The sphere's own radius counts too: a centre just outside the box may still touch.
        const float grow = m + ri;
        if (all_colliders.misses(xi, grow)) continue;
        for (std::size_t c = 0; c < colliders.size(); ++c) {
          if (collider_box[c].misses(xi, grow)) continue;
          float t = closest_segment_parameter(ca[c], cb[c], xi);
          Vec3 q = ca[c] + t * (cb[c] - ca[c]);
          float reach = ri + cr[c] + m + collider_margin[c];
          if ((xi - q).squaredNorm() >= reach * reach) continue;
          std::uint32_t id = kColliderTag | static_cast<std::uint32_t>(c);
          out.statics.push_back(search.make(i, id, mat, search.warm(i, id)));
        }
      }
    }
  }
}

}  // namespace ballpit
