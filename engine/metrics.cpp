#include "engine/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/world.h"

namespace ballpit {

namespace {

void measure_overlaps(const World& world, Metrics& m) {
  const SphereTable& s = world.spheres;
  auto x = s.position();
  auto r = s.radius();
  const std::size_t n = s.size();
  if (n < 2) return;
  float rmax = *std::max_element(r.begin(), r.end());
  const double cell = 2.0 * rmax;
  auto coord = [&](float p) { return static_cast<std::int64_t>(std::floor(p / cell)) + (1 << 20); };
  auto pack = [](std::int64_t cx, std::int64_t cy, std::int64_t cz) {
    return (static_cast<std::uint64_t>(cx) << 42) | (static_cast<std::uint64_t>(cy) << 21) |
           static_cast<std::uint64_t>(cz);
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells(n);
  for (std::size_t i = 0; i < n; ++i)
    cells[i] = {pack(coord(x[i].x()), coord(x[i].y()), coord(x[i].z())), static_cast<std::uint32_t>(i)};
  std::sort(cells.begin(), cells.end());
  double sum = 0.0;
  for (std::size_t a = 0; a < n; ++a) {
    std::uint32_t i = cells[a].second;
    std::int64_t cx = coord(x[i].x()), cy = coord(x[i].y()), cz = coord(x[i].z());
    // z is the key's lowest field, so a neighbour column's three cells are three adjacent keys:
    // one search a column, not one a cell (27 binary searches a sphere took about 1.3 s at 1M),
    // and the cells are visited in the same order as before, so the sums are too.
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        const std::uint64_t first = pack(cx + dx, cy + dy, cz - 1), last = pack(cx + dx, cy + dy, cz + 1);
        auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(first, 0u));
        for (; it != cells.end() && it->first <= last; ++it) {
          std::uint32_t j = it->second;
          if (j <= i) continue;
          double overlap = static_cast<double>(r[i] + r[j]) - (x[j] - x[i]).cast<double>().norm();
          if (overlap <= 0.0) continue;
          double frac = overlap / std::min(r[i], r[j]);
          m.max_penetration_r = std::max(m.max_penetration_r, frac);
          sum += frac;
          ++m.overlapping_pairs;
        }
      }
  }
  if (m.overlapping_pairs) m.mean_penetration_r = sum / static_cast<double>(m.overlapping_pairs);
}

}  // namespace

double kinetic_energy(const World& world) {
  const SphereTable& s = world.spheres;
  auto v = s.velocity();
  auto inv_mass = s.inv_mass();
  auto r = s.radius();
  auto spin = s.has_angular() ? s.angular_velocity() : std::span<const Vec3>{};
  double ke = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double m = 1.0 / inv_mass[i];
    ke += 0.5 * m * v[i].cast<double>().squaredNorm();
    if (!spin.empty()) ke += 0.2 * m * r[i] * r[i] * spin[i].cast<double>().squaredNorm();  // 1/2 I w^2
  }
  return ke;
}

Metrics measure(const World& world) {
  Metrics m;
  m.kinetic_energy_j = kinetic_energy(world);
  const SphereTable& s = world.spheres;
  auto x = s.position();
  auto v = s.velocity();
  auto r = s.radius();
  auto inv_mass = s.inv_mass();
  const Pit& pit = world.pit;
  for (std::size_t i = 0; i < s.size(); ++i) {
    double mass = 1.0 / inv_mass[i];
    double speed2 = v[i].cast<double>().squaredNorm();
    m.max_speed_mps = std::max(m.max_speed_mps, std::sqrt(speed2));
    for (int a = 0; a < 3; ++a) m.momentum[a] += mass * v[i][a];
    if (!pit.inside(x[i], r[i])) ++m.escaped;
    for (int p = 0; p < pit.plane_count(); ++p) {
      if (!pit.plane_applies(p, x[i])) continue;
      double gap = pit.plane_normal(p).dot(x[i]) - pit.plane_offset(p) - r[i];
      // Only spheres near the wall: one flown over it is escaped, not inside it.
      if (gap < 0.0 && gap > -2.0 * r[i]) m.max_wall_penetration_r = std::max(m.max_wall_penetration_r, -gap / r[i]);
    }
  }
  measure_overlaps(world, m);
  return m;
}

}  // namespace ballpit
