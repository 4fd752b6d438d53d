#include "systems/integrate.h"

#include "engine/world.h"

namespace ballpit {

void integrate_velocities(SphereTable& spheres, const Vec3& gravity, float h, const SolverSettings& s) {
  auto v = spheres.mut_velocity();
  auto asleep = spheres.asleep();
  auto inv_mass = spheres.inv_mass();
  const Vec3 dv = gravity * h;
  // Implicit damping 1 / (1 + c h): stable for any c and h, unlike 1 - c h.
  const float linear = 1.0f / (1.0f + h * s.linear_damping);
  const std::int64_t n = static_cast<std::int64_t>(v.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i] || inv_mass[i] == 0.0f) continue;
    v[i] = (v[i] + dv) * linear;
  }
  if (spheres.has_angular() && s.angular_damping > 0.0f) {
    auto w = spheres.mut_angular_velocity();
    const float angular = 1.0f / (1.0f + h * s.angular_damping);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) w[i] *= angular;
  }
}

void integrate_positions(SphereTable& spheres, float h, const Vec3& gravity, std::span<const std::uint8_t> pushed,
                         std::span<const Vec3> push_out) {
  auto x = spheres.mut_position();
  auto v = spheres.velocity();
  auto asleep = spheres.asleep();
  // v was kicked by g h at the start of the substep, so v h overshoots the parabola by this.
  const Vec3 flight_correction = -0.5f * h * h * gravity;
  const bool all_free = pushed.empty();
  const std::int64_t n = static_cast<std::int64_t>(x.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i]) continue;
    x[i] += v[i] * h;
    if (all_free || !pushed[i]) x[i] += flight_correction;
    if (!push_out.empty()) x[i] += push_out[i] * h;
  }
}

void integrate_velocities(SolverBodies& bodies, const Vec3& gravity, float h, const SolverSettings& s) {
  const Vec3 dv = gravity * h;
  const float linear = 1.0f / (1.0f + h * s.linear_damping);
  const float angular = 1.0f / (1.0f + h * s.angular_damping);  // spin r w damps as w does
  const std::int64_t n = static_cast<std::int64_t>(bodies.rows);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    SolverBody& b = bodies.body[i];
    b.pseudo = {0.0f, 0.0f, 0.0f, b.pseudo.w};
    Quad& spin = b.spin;
    spin.w = 0.0f;  // pushed
    Quad& v = b.velocity;
    if (v.w == 0.0f) continue;  // asleep: immobile this step
    v = {(v.x + dv.x()) * linear, (v.y + dv.y()) * linear, (v.z + dv.z()) * linear, v.w};
    if (s.angular_damping > 0.0f) spin = {spin.x * angular, spin.y * angular, spin.z * angular, 0.0f};
  }
}

void integrate_positions(SolverBodies& bodies, float h, const Vec3& gravity) {
  const Vec3 flight_correction = -0.5f * h * h * gravity;
  const std::int64_t n = static_cast<std::int64_t>(bodies.rows);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    SolverBody& b = bodies.body[i];
    const Quad& v = b.velocity;
    if (v.w == 0.0f) continue;
    Quad& x = b.position;
    const Quad& p = b.pseudo;
    float px = x.x + v.x * h, py = x.y + v.y * h, pz = x.z + v.z * h;
    if (b.spin.w == 0.0f) {  // not pushed: free flight
      px += flight_correction.x();
      py += flight_correction.y();
      pz += flight_correction.z();
    }
    x = {px + p.x * h, py + p.y * h, pz + p.z * h, x.w};
  }
}

Access IntegrateSystem::access() const {
  Access a;
  a.reads = {ColumnId::Gravity, ColumnId::SphereInvMass, ColumnId::SphereSleep};
  a.writes = {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity};
  return a;
}

void IntegrateSystem::run(World& world) {
  integrate_velocities(world.spheres, world.gravity(), world.step(), world.solver);
  integrate_positions(world.spheres, world.step(), world.gravity());
}

}  // namespace ballpit
