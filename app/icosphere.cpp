#include "app/icosphere.h"

#include <cmath>
#include <map>
#include <utility>

namespace ballpit {

IcosphereMesh make_icosphere(int subdivisions) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  IcosphereMesh m;
  m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& p : m.positions) p.normalize();
  m.indices = {0, 11, 5, 0, 5, 1,  0, 1, 7,   0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
               11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4,  3, 4, 2,   3, 2, 6, 3, 6, 8,
               3, 8, 9,  4, 9, 5,  2, 4, 11, 6, 2, 10, 8, 6, 7,   9, 8, 1};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint16_t, std::uint16_t>, std::uint16_t> midpoint;
    auto mid = [&](std::uint16_t a, std::uint16_t b) {
      auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      auto i = static_cast<std::uint16_t>(m.positions.size());
      m.positions.push_back((m.positions[a] + m.positions[b]).normalized());
      midpoint.emplace(key, i);
      return i;
    };
    std::vector<std::uint16_t> next;
    for (std::size_t i = 0; i < m.indices.size(); i += 3) {
      std::uint16_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
      std::uint16_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices = std::move(next);
  }
  // Volume of the unit-vertex mesh: sum of the tetrahedra it makes with the centre.
  double volume = 0.0;
  for (std::size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3& a = m.positions[m.indices[i]];
    const Vec3& b = m.positions[m.indices[i + 1]];
    const Vec3& c = m.positions[m.indices[i + 2]];
    volume += a.dot(b.cross(c)) / 6.0;
  }
  m.scale = static_cast<float>(std::cbrt((4.0 / 3.0 * M_PI) / volume));
  for (Vec3& p : m.positions) p *= m.scale;
  return m;
}

}  // namespace ballpit
