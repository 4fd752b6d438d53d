// Math vocabulary: Eigen fixed-size types under short names. Hot columns store Vec3 (12 bytes,
// unaligned) rather than padded Vec4 because the solver touches two random spheres per contact
// and the tighter stride keeps more of the pile in cache.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ballpit {

using Vec2 = Eigen::Vector2f;
using Vec3 = Eigen::Vector3f;
using Vec4 = Eigen::Vector4f;
using Mat3 = Eigen::Matrix3f;
using Mat4 = Eigen::Matrix4f;
using Quat = Eigen::Quaternionf;
using Affine3 = Eigen::Affine3f;

inline bool all_finite(const Vec3& v) { return v.allFinite(); }

}  // namespace ballpit
