// Joint colliders: the kinematic shapes a character pushes balls with, as structure-of-arrays
// in world space. A sphere collider is a capsule whose two ends coincide, so the narrowphase and
// solver handle one shape. Colliders have infinite mass: contacts move balls, never colliders.
//
// Each end carries the surface velocity the animation gives it at this step; points between the
// ends move with the linear blend of the two (exact for a rigid bone that does not spin about
// its own axis, which is what a capsule along a bone can represent).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

#include "engine/access.h"
#include "engine/aligned_vector.h"
#include "engine/entity.h"
#include "engine/math.h"

namespace ballpit {

enum class ColliderShape : std::uint8_t { Sphere, Capsule };

struct ColliderDesc {
  ColliderShape shape = ColliderShape::Sphere;
  Vec3 a = Vec3::Zero();           // sphere centre, or capsule segment start (unit: m)
  Vec3 b = Vec3::Zero();           // capsule segment end; equal to a for a sphere (unit: m)
  float radius = 0.05f;            // (unit: m)
  Vec3 velocity_a = Vec3::Zero();  // surface velocity at a (unit: m/s)
  Vec3 velocity_b = Vec3::Zero();  // surface velocity at b (unit: m/s)
  Entity owner;                    // the character this collider belongs to
  std::uint16_t bone = 0;          // bone index in the owner's skeleton
};

class ColliderTable {
 public:
  // Throws ballpit::Error naming the collider row if geometry is not finite or radius <= 0.
  std::uint32_t add(const ColliderDesc& d);
  void clear();
  std::size_t size() const { return radius_.size(); }

  // Updates geometry and surface velocity of an existing row (the character systems do this
  // every step).
  void set_pose(std::uint32_t row, const Vec3& a, const Vec3& b, const Vec3& velocity_a,
                const Vec3& velocity_b);

  std::span<const ColliderShape> shape() const { return read(shape_); }
  std::span<const Vec3> a() const { return read(a_); }
  std::span<const Vec3> b() const { return read(b_); }
  std::span<const float> radius() const { return read(radius_); }
  std::span<const Vec3> velocity_a() const { return read(velocity_a_); }
  std::span<const Vec3> velocity_b() const { return read(velocity_b_); }
  // The fastest point of row k's surface: a capsule's velocity is linear along its segment, so
  // one of its ends (unit: m/s).
  float speed(std::size_t k) const { return std::max(velocity_a()[k].norm(), velocity_b()[k].norm()); }
  std::span<const Entity> owner() const { return read(owner_); }
  std::span<const std::uint16_t> bone() const { return read(bone_); }
  std::span<float> mut_radius() {
    check_access(ColumnId::Colliders, true);
    return {radius_.data(), radius_.size()};
  }

 private:
  template <class T>
  static std::span<const T> read(const Column<T>& c) {
    check_access(ColumnId::Colliders, false);
    return {c.data(), c.size()};
  }

  Column<ColliderShape> shape_;
  Column<Vec3> a_;
  Column<Vec3> b_;
  Column<float> radius_;
  Column<Vec3> velocity_a_;
  Column<Vec3> velocity_b_;
  Column<Entity> owner_;
  Column<std::uint16_t> bone_;
};

// Closest point to p on segment [a, b], as the parameter t in [0, 1].
inline float closest_segment_parameter(const Vec3& a, const Vec3& b, const Vec3& p) {
  Vec3 ab = b - a;
  float len2 = ab.squaredNorm();
  if (len2 <= 0.0f) return 0.0f;
  float t = (p - a).dot(ab) / len2;
  return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

}  // namespace ballpit
