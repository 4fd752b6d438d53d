#include "engine/settings.h"

#include <algorithm>
#include <cmath>

namespace ballpit {

Material combine(const Material& a, const Material& b) {
  return {std::max(a.restitution, b.restitution), std::sqrt(a.friction * b.friction)};
}

Vec3 Pit::plane_normal(int i) const {
  switch (i) {
    case 0: return Vec3(0, 1, 0);
    case 1: return Vec3(1, 0, 0);
    case 2: return Vec3(-1, 0, 0);
    case 3: return Vec3(0, 0, 1);
    case 4: return Vec3(0, 0, -1);
    default: return Vec3(0, -1, 0);
  }
}

float Pit::plane_offset(int i) const {
  switch (i) {
    case 0: return 0.0f;
    case 5: return -wall_height;
    default: return -half_width;
  }
}

bool Pit::inside(const Vec3& p, float radius) const {
  // Half a radius of slack: a sphere pressed into a wall is still in the pit.
  float limit = half_width + 0.5f * radius;
  return std::abs(p.x()) <= limit && std::abs(p.z()) <= limit && p.y() >= -0.5f * radius &&
         (!closed || p.y() <= wall_height + 0.5f * radius);
}

}  // namespace ballpit
