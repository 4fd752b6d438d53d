#include "systems/sleeping.h"

#include <atomic>

#include "engine/world.h"

namespace ballpit {

namespace {

// Several slabs may wake the same sleeper at once; every write stores the same values, so the
// outcome is deterministic, and atomic_ref keeps it free of data races.
void wake(std::uint8_t& asleep, float& still) {
  std::atomic_ref<std::uint8_t>(asleep).store(0, std::memory_order_relaxed);
  std::atomic_ref<float>(still).store(0.0f, std::memory_order_relaxed);
}

}  // namespace

Access WakeSystem::access() const {
  Access a;
  a.reads = {ColumnId::SphereVelocity, ColumnId::Contacts, ColumnId::Colliders};
  a.writes = {ColumnId::SphereSleep};
  return a;
}

Access SleepSystem::access() const {
  Access a;
  a.reads = {ColumnId::SphereRadius, ColumnId::Contacts};
  a.writes = {ColumnId::SphereSleep, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity};
  return a;
}

void wake_approached(World& world) {
  SphereTable& spheres = world.spheres;
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  auto v = spheres.velocity();
  auto cva = world.colliders.velocity_a();
  auto cvb = world.colliders.velocity_b();
  const float wake2 = world.solver.wake_speed * world.solver.wake_speed;
  std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const int count = static_cast<int>(slabs.size());

  auto check = [&](const Contact& c) {
    if (c.b & kColliderTag) {
      std::uint32_t k = c.b & ~kTagMask;
      if (k < cva.size() && asleep[c.a] && std::max(cva[k].squaredNorm(), cvb[k].squaredNorm()) > wake2)
        wake(asleep[c.a], still[c.a]);
      return;
    }
    if (c.b & kTagMask) return;
    const bool sa = asleep[c.a], sb = asleep[c.b];
    if (sa == sb) return;
    std::uint32_t sleeper = sa ? c.a : c.b, mover = sa ? c.b : c.a;
    if (v[mover].squaredNorm() > wake2) wake(asleep[sleeper], still[sleeper]);
  };
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < count; ++k) {
    for (const Contact& c : slabs[k].pairs) check(c);
    for (const Contact& c : slabs[k].statics) check(c);
    for (const Contact& c : slabs[k].serial) check(c);
  }
}

void update_sleep(World& world) {
  SphereTable& spheres = world.spheres;
  const SolverSettings& s = world.solver;
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  auto v = spheres.mut_velocity();
  auto r = spheres.radius();
  const bool angular = spheres.has_angular();
  auto w = angular ? spheres.mut_angular_velocity() : std::span<Vec3>{};

  auto& requests = world.contacts.wake_requests;
  if (requests.size() == spheres.size()) {
    const std::int64_t rows = static_cast<std::int64_t>(requests.size());
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < rows; ++i)
      if (requests[i]) {
        asleep[i] = 0;
        still[i] = 0.0f;
      }
  }

  const float dt = world.step();
  const float sleep2 = s.sleep_speed * s.sleep_speed;
  const std::int64_t n = static_cast<std::int64_t>(spheres.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i]) continue;
    float spin = angular ? w[i].squaredNorm() * r[i] * r[i] : 0.0f;
    if (v[i].squaredNorm() < sleep2 && spin < sleep2) {
      still[i] += dt;
      if (still[i] >= s.sleep_time) {
        asleep[i] = 1;
        v[i].setZero();
        if (angular) w[i].setZero();
      }
    } else {
      still[i] = 0.0f;
    }
  }
}

}  // namespace ballpit
