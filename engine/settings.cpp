#include "engine/settings.h"

#include <algorithm>
#include <cmath>

namespace ballpit {

Material combine(const Material& a, const Material& b) {
  return {std::max(a.restitution, b.restitution), std::sqrt(a.friction * b.friction)};
}

bool Pit::inside(const Vec3& p, float radius) const {
  // Half a radius of slack: a sphere pressed into a wall is still in the pit.
  float limit = half_width + 0.5f * radius;
  return std::abs(p.x()) <= limit && std::abs(p.z()) <= limit && p.y() >= -0.5f * radius &&
         (!closed || p.y() <= wall_height + 0.5f * radius);
}

}  // namespace ballpit
