#include "systems/narrowphase.h"

#include <algorithm>
#include <cmath>

#include "engine/world.h"

namespace ballpit {

namespace {

struct SlabSearch {
  const SpatialGrid& grid;
  std::span<const Vec3> x;
  std::span<const float> r;
  std::span<const std::uint8_t> asleep;
  std::span<const std::uint16_t> material;
  std::span<const std::uint32_t> entity;
  const NarrowphaseScratch& scratch;
  const std::vector<Material>& pair_material;  // materials x materials, combined
  std::size_t material_count;
  const ContactSet& previous;                  // warm-start cache of the last step
  std::span<const std::uint32_t> new_to_old;

  // Is row j in the slab or the next one? Rows are sorted by cell key and a slab is a key range,
  // so it is a row range: two lookups instead of a division of j's key per pair.
  bool local(std::uint32_t j, int slab) const {
    return j >= grid.slab_row_begin(slab) && j < grid.slab_row_begin(std::min(slab + 2, grid.nx));
  }

  const WarmStartEntry* warm(std::uint32_t old_row, std::uint32_t partner) const {
    if (old_row + 1 >= previous.warm_begin.size()) return nullptr;
    for (std::uint32_t k = previous.warm_begin[old_row]; k < previous.warm_begin[old_row + 1]; ++k)
      if (previous.warm[k].partner == partner) return &previous.warm[k];
    return nullptr;
  }

  // `reversed`: the cached contact had a and b the other way round (row order decides which
  // sphere generates a pair, and rows are re-sorted every step), so its friction impulse, which
  // acts on a as -F and on b as +F, changes sign. The normal impulse is along a -> b either way.
  Contact make(std::uint32_t a, std::uint32_t b, const Material& m, const WarmStartEntry* w,
               bool reversed = false) const {
    Contact c{a, b, 0.0f, Vec3::Zero(), m.friction, m.restitution, 0.0f, false, Vec3::Zero(), 0.0f};
    if (w) {
      c.normal_impulse = w->normal_impulse;
      c.friction_impulse = reversed ? Vec3(-w->friction_impulse) : w->friction_impulse;
      c.loaded_last_step = w->normal_impulse > 0.0f;
    }
    return c;
  }

  void add_pair(std::uint32_t i, std::uint32_t j, int slab, SlabContacts& out) const {
    const Material& m = pair_material[material[i] * material_count + material[j]];
    const WarmStartEntry* w = nullptr;
    bool reversed = false;
    if (!new_to_old.empty()) {
      w = warm(new_to_old[i], entity[j]);
      if (!w) reversed = (w = warm(new_to_old[j], entity[i])) != nullptr;
    }
    auto& list = local(j, slab) ? out.pairs : out.serial;
    list.push_back(make(i, j, m, w, reversed));
  }

  bool touching_soon(std::uint32_t i, std::uint32_t j) const {
    if (asleep[i] && asleep[j]) return false;
    float reach = r[i] + r[j] + scratch.margin[i] + scratch.margin[j];
    return (x[j] - x[i]).squaredNorm() < reach * reach;
  }

  // Does the slow sphere i own the pair with j? Fast spheres record their own pairs.
  bool slow_owns(std::uint32_t i, std::uint32_t j) const { return j > i && !scratch.fast[j]; }

  // A fast sphere owns pairs with slow spheres, and with fast ones of smaller margin (ties by
  // row), so exactly one side records each pair.
  bool fast_owns(std::uint32_t i, std::uint32_t j) const {
    if (i == j) return false;
    if (!scratch.fast[j]) return true;
    float mi = scratch.margin[i], mj = scratch.margin[j];
    return mj < mi || (mj == mi && j > i);
  }

  void scan_rows(std::uint32_t i, std::uint32_t begin, std::uint32_t end, bool fast, int slab, SlabContacts& out) const {
    for (std::uint32_t j = begin; j < end; ++j) {
      if (!(fast ? fast_owns(i, j) : slow_owns(i, j))) continue;
      if (touching_soon(i, j)) add_pair(i, j, slab, out);
    }
  }

  // Cells (cx, y0..y1, cz), y clipped to the grid: consecutive keys, so one row range, visited
  // in the order the cells one by one would visit them.
  void scan_column(std::uint32_t i, int cx, int y0, int y1, int cz, bool fast, int slab, SlabContacts& out) const {
    if (cx >= grid.nx || cz < 0 || cz >= grid.nz) return;
    y0 = std::max(y0, 0);
    y1 = std::min(y1, grid.ny - 1);
    if (y0 > y1) return;
    scan_rows(i, grid.cell_start[grid.key(cx, y0, cz)], grid.cell_start[grid.key(cx, y1, cz) + 1], fast, slab,
              out);
  }

  void grid_pairs(std::uint32_t i, int slab, SlabContacts& out) const {
    std::uint32_t k = grid.cell_of_row[i];
    int cy = static_cast<int>(k % grid.ny);
    int cz = static_cast<int>((k / grid.ny) % grid.nz);
    int cx = slab;
    if (!scratch.fast[i]) {
      // Forward half of the 27-cell neighbourhood: cells with a larger key, plus the own cell
      // (partners of larger row only). Keys grow with y, then z, then x, so rows do too, and
      // the cells of one (x, z) column that differ in y are one range of rows.
      scan_column(i, cx, cy, cy + 1, cz, false, slab, out);
      scan_column(i, cx, cy - 1, cy + 1, cz + 1, false, slab, out);
      for (int dz = -1; dz <= 1; ++dz) scan_column(i, cx + 1, cy - 1, cy + 1, cz + dz, false, slab, out);
      return;
    }
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
    for (int ax = x0; ax <= x1; ++ax)
      for (int az = z0; az <= z1; ++az) scan_column(i, ax, y0, y1, az, true, slab, out);
  }

  void naive_pairs(std::uint32_t i, int slab, SlabContacts& out) const {
    const std::uint32_t n = static_cast<std::uint32_t>(x.size());
    for (std::uint32_t j = 0; j < n; ++j) {
      bool owns = scratch.fast[i] ? fast_owns(i, j) : slow_owns(i, j);
      if (owns && touching_soon(i, j)) add_pair(i, j, slab, out);
    }
  }
};

}  // namespace

float speculative_margin(float speed, float dt, float gravity, float radius) {
  return speed * dt + gravity * dt * dt + kMinMarginFraction * radius;
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
  const SphereTable& spheres = world.spheres;
  const SpatialGrid& grid = world.grid;
  const std::size_t n = spheres.size();
  const float dt = world.step();
  const float g = world.gravity().norm();
  auto x = spheres.position();
  auto v = spheres.velocity();
  auto r = spheres.radius();
  auto asleep = spheres.asleep();

  scratch.margin.resize(n);
  scratch.fast.resize(n);
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i) {
    float m = asleep[i] ? kMinMarginFraction * r[i] : speculative_margin(v[i].norm(), dt, g, r[i]);
    scratch.margin[i] = m;
    scratch.fast[i] = m > grid.slow_margin;
  }

  const std::size_t mc = world.materials.size();
  std::vector<Material> pair_material(mc * mc);
  for (std::size_t a = 0; a < mc; ++a)
    for (std::size_t b = 0; b < mc; ++b) pair_material[a * mc + b] = combine(world.materials[a], world.materials[b]);
  std::vector<Material> pit_material(mc);
  for (std::size_t a = 0; a < mc; ++a) pit_material[a] = combine(world.materials[a], world.pit.material);

  // Joint colliders: the box around all of them (grown by the widest reach) filters spheres
  // cheaply; only spheres inside test each collider.
  const ColliderTable& colliders = world.colliders;
  auto ca = colliders.a();
  auto cb = colliders.b();
  auto cr = colliders.radius();
  auto cva = colliders.velocity_a();
  auto cvb = colliders.velocity_b();
  std::vector<float> collider_margin(colliders.size());
  Vec3 box_lo = Vec3::Constant(1e30f), box_hi = Vec3::Constant(-1e30f);
  for (std::size_t c = 0; c < colliders.size(); ++c) {
    collider_margin[c] = std::max(cva[c].norm(), cvb[c].norm()) * dt;
    float grow = cr[c] + collider_margin[c];
    box_lo = box_lo.cwiseMin(ca[c].cwiseMin(cb[c]) - Vec3::Constant(grow));
    box_hi = box_hi.cwiseMax(ca[c].cwiseMax(cb[c]) + Vec3::Constant(grow));
  }
  const Material collider_material = world.pit.material;

  ContactSet& contacts = world.contacts;
  const int slabs = grid.nx;
  // Last step's cache stays valid while this step's lists are rebuilt: the solver writes a
  // fresh cache at its end.
  if (contacts.slabs.size() != static_cast<std::size_t>(slabs)) contacts.slabs.resize(slabs);
  SlabSearch search{grid,
                    x,
                    r,
                    asleep,
                    spheres.material(),
                    spheres.entity_index(),
                    scratch,
                    pair_material,
                    mc,
                    contacts,
                    grid.new_to_old};
  const bool naive = world.solver.narrowphase == NarrowphaseMode::Naive;
  const Pit& pit = world.pit;
  const int planes = pit.plane_count();

#pragma omp parallel for schedule(dynamic, 1)
  for (int s = 0; s < slabs; ++s) {
    SlabContacts& out = contacts.slabs[s];
    out.pairs.clear();
    out.statics.clear();
    out.serial.clear();
    const std::uint32_t begin = grid.slab_row_begin(s), end = grid.slab_row_begin(s + 1);
    for (std::uint32_t i = begin; i < end; ++i) {
      if (naive) search.naive_pairs(i, s, out);
      else search.grid_pairs(i, s, out);
      const float m = scratch.margin[i];
      // Sleepers get their planes and colliders too: the wake system may wake them before
      // the solver runs, and a woken ball must still have its floor.
      for (int p = 0; p < planes; ++p) {
        if (!pit.plane_applies(p, x[i])) continue;
        float gap = pit.plane_normal(p).dot(x[i]) - pit.plane_offset(p) - r[i];
        if (gap < m) {
          std::uint32_t id = kPlaneTag | static_cast<std::uint32_t>(p);
          const WarmStartEntry* w = search.new_to_old.empty() ? nullptr : search.warm(search.new_to_old[i], id);
          out.statics.push_back(search.make(i, id, pit_material[search.material[i]], w));
        }
      }
      if (colliders.size() == 0) continue;
      // The sphere's own radius counts too: a centre just outside the box may still touch.
      const float grow = m + r[i];
      if ((x[i].array() < box_lo.array() - grow).any() || (x[i].array() > box_hi.array() + grow).any()) continue;
      for (std::size_t c = 0; c < colliders.size(); ++c) {
        float t = closest_segment_parameter(ca[c], cb[c], x[i]);
        Vec3 q = ca[c] + t * (cb[c] - ca[c]);
        float reach = r[i] + cr[c] + m + collider_margin[c];
        if ((x[i] - q).squaredNorm() >= reach * reach) continue;
        std::uint32_t id = kColliderTag | static_cast<std::uint32_t>(c);
        const WarmStartEntry* w = search.new_to_old.empty() ? nullptr : search.warm(search.new_to_old[i], id);
        Material mat = combine(world.materials[search.material[i]], collider_material);
        out.statics.push_back(search.make(i, id, mat, w));
      }
    }
  }
}

}  // namespace ballpit
