#include "engine/collider_table.h"

#include <cmath>

#include "engine/error.h"

namespace ballpit {

std::uint32_t ColliderTable::add(const ColliderDesc& d) {
  std::uint32_t row = static_cast<std::uint32_t>(size());
  auto fail = [&](const std::string& what) {
    throw Error("collider " + std::to_string(row) + " (bone " + std::to_string(d.bone) + "): " + what);
  };
  if (!all_finite(d.a) || !all_finite(d.b)) fail("end points must be finite");
  if (!all_finite(d.velocity_a) || !all_finite(d.velocity_b)) fail("velocities must be finite");
  if (!(d.radius > 0.0f) || !std::isfinite(d.radius))
    fail("radius must be a finite number > 0 m, got " + std::to_string(d.radius));
  check_access(ColumnId::Colliders, true);
  shape_.push_back(d.shape);
  a_.push_back(d.a);
  b_.push_back(d.shape == ColliderShape::Sphere ? d.a : d.b);
  radius_.push_back(d.radius);
  velocity_a_.push_back(d.velocity_a);
  velocity_b_.push_back(d.shape == ColliderShape::Sphere ? d.velocity_a : d.velocity_b);
  owner_.push_back(d.owner);
  bone_.push_back(d.bone);
  return row;
}

void ColliderTable::clear() {
  shape_.clear();
  a_.clear();
  b_.clear();
  radius_.clear();
  velocity_a_.clear();
  velocity_b_.clear();
  owner_.clear();
  bone_.clear();
}

void ColliderTable::set_pose(std::uint32_t row, const Vec3& a, const Vec3& b, const Vec3& velocity_a,
                             const Vec3& velocity_b) {
  check_access(ColumnId::Colliders, true);
  a_[row] = a;
  b_[row] = shape_[row] == ColliderShape::Sphere ? a : b;
  velocity_a_[row] = velocity_a;
  velocity_b_[row] = shape_[row] == ColliderShape::Sphere ? velocity_a : velocity_b;
}

}  // namespace ballpit
