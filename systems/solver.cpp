#include "systems/solver.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/world.h"
#include "systems/integrate.h"

namespace ballpit {

namespace {

// For a solid sphere r^2 / I = 5 / (2 m): how much harder a contact point is to slide than the
// centre is to push.
constexpr float kSphereAngularFactor = 2.5f;

// Box2D's soft constraint coefficients for a spring of `hertz` and damping ratio `zeta` over
// a substep h (Catto, "Solver2D", 2024).
struct Softness {
  float bias_rate = 0.0f;
  float mass_scale = 1.0f;
  float impulse_scale = 0.0f;
};

Softness make_softness(float hertz, float zeta, float h) {
  float omega = 2.0f * std::numbers::pi_v<float> * hertz;
  float a1 = 2.0f * zeta + h * omega;
  float a2 = h * omega * a1;
  float a3 = 1.0f / (1.0f + a2);
  return {omega / a1, a2 * a3, a3};
}

enum class Pass { WarmStart, Solve, Relax };

struct Solver {
  Vec3* x;
  Vec3* v;
  Vec3* w;  // null without angular state
  const float* r;
  const float* inv_mass;
  const std::uint8_t* asleep;
  const Pit& pit;
  std::span<const Vec3> ca, cb, cva, cvb;
  std::span<const float> cr;
  float h, inv_h;
  Softness soft;
  float push_out_speed;
  float restitution_threshold;

  float mobility(std::uint32_t i) const { return asleep[i] ? 0.0f : inv_mass[i]; }

  // The contact frame and gap for a contact: n points from a toward b.
  struct Frame {
    Vec3 n;
    float gap;
    Vec3 surface_velocity;  // of a static partner at the contact (unit: m/s)
  };

  Frame pair_frame(std::uint32_t a, std::uint32_t b) const {
    Vec3 d = x[b] - x[a];
    float dist = d.norm();
    Vec3 n = dist > 1e-9f ? Vec3(d / dist) : Vec3(0.0f, 1.0f, 0.0f);
    return {n, dist - r[a] - r[b], Vec3::Zero()};
  }

  Frame static_frame(std::uint32_t a, std::uint32_t b) const {
    if (b & kPlaneTag) {
      int p = static_cast<int>(b & ~kTagMask);
      Vec3 np = pit.plane_normal(p);
      return {-np, np.dot(x[a]) - pit.plane_offset(p) - r[a], Vec3::Zero()};
    }
    std::uint32_t c = b & ~kTagMask;
    float t = closest_segment_parameter(ca[c], cb[c], x[a]);
    Vec3 q = ca[c] + t * (cb[c] - ca[c]);
    Vec3 d = q - x[a];
    float dist = d.norm();
    Vec3 n = dist > 1e-9f ? Vec3(d / dist) : Vec3(0.0f, -1.0f, 0.0f);
    return {n, dist - r[a] - cr[c], (1.0f - t) * cva[c] + t * cvb[c]};
  }

  // One contact, one pass. For a static partner, vb is a scratch copy of its surface velocity
  // and mb = 0, so nothing the contact does to "b" survives.
  template <Pass pass>
  void contact(Contact& c, const Frame& f, Vec3& vb, Vec3* wb, float mb, float rb) const {
    const std::uint32_t a = c.a;
    const float ma = mobility(a);
    if (ma + mb == 0.0f) return;
    const bool idle = c.normal_impulse == 0.0f && c.friction_impulse.isZero(0.0f);
    if (pass == Pass::WarmStart && idle) return;
    Vec3& va = v[a];
    Vec3* wa = w ? &w[a] : nullptr;
    const float ra = r[a];
    const Vec3& n = f.n;
    const float ka = wa ? kSphereAngularFactor * ma / ra : 0.0f;  // spin per unit tangential impulse
    const float kb = wb ? kSphereAngularFactor * mb / rb : 0.0f;

    auto apply = [&](const Vec3& impulse) {
      va -= ma * impulse;
      vb += mb * impulse;
    };
    auto apply_tangential = [&](const Vec3& impulse) {
      apply(impulse);
      Vec3 torque_axis = n.cross(impulse);
      if (wa) *wa -= ka * torque_axis;
      if (wb) *wb -= kb * torque_axis;
    };

    if (pass == Pass::WarmStart) {
      c.friction_impulse -= n * n.dot(c.friction_impulse);
      apply(c.normal_impulse * n);
      apply_tangential(c.friction_impulse);
      return;
    }

    // Spin adds nothing along the normal of a sphere contact, so vn needs no cross products.
    float vn = (vb - va).dot(n);
    // A speculative contact that will not close this substep, and carries nothing: skip.
    if (idle && f.gap > 0.0f && vn + f.gap * inv_h >= 0.0f) return;
    const float normal_mass = 1.0f / (ma + mb);

    // An impact this substep: restitution now, with the gap closed before it remembered so
    // the move after it can be shortened by exactly the travel it should not have made. Only
    // an unloaded contact can be struck: in a loaded one (a pile) the warm start moves the
    // velocities around, and reading that as an impact would pump energy into the pile.
    float impact = 0.0f;
    if (pass == Pass::Solve && c.restitution > 0.0f && c.normal_impulse == 0.0f &&
        vn < -restitution_threshold && f.gap + vn * h < 0.0f) {
      impact = -(1.0f + c.restitution) * vn * normal_mass;
      apply(impact * n);
      c.impact_shift = (1.0f + c.restitution) * std::max(f.gap, 0.0f);
      vn = -c.restitution * vn;
    }

    float bias = 0.0f, mass_scale = 1.0f, impulse_scale = 0.0f;
    if (f.gap > 0.0f) {
      bias = f.gap * inv_h;  // speculative: may close the gap this substep, not more
    } else if (pass == Pass::Solve) {
      bias = std::max(soft.bias_rate * f.gap, -push_out_speed);
      mass_scale = soft.mass_scale;
      impulse_scale = soft.impulse_scale;
    }
    float delta = -normal_mass * mass_scale * (vn + bias) - impulse_scale * c.normal_impulse;
    float total = std::max(c.normal_impulse + delta, 0.0f);
    delta = total - c.normal_impulse;
    c.normal_impulse = total;
    apply(delta * n);

    const float limit = c.friction * (c.normal_impulse + impact);
    if (limit == 0.0f && c.friction_impulse.isZero(0.0f)) return;
    Vec3 at_a = va + (wa ? Vec3(wa->cross(ra * n)) : Vec3::Zero());
    Vec3 at_b = vb + (wb ? Vec3(wb->cross(-rb * n)) : Vec3::Zero());
    Vec3 vr = at_b - at_a;
    Vec3 vt = vr - n * n.dot(vr);
    const float tangent_mass = 1.0f / (ma + mb + ka * ra + kb * rb);
    Vec3 old = c.friction_impulse;
    Vec3 next = old - tangent_mass * vt;
    next -= n * n.dot(next);
    const float len2 = next.squaredNorm();
    if (len2 > limit * limit) next *= limit / std::sqrt(len2);
    c.friction_impulse = next;
    apply_tangential(next - old);
  }

  template <Pass pass>
  void pair(Contact& c) const {
    const std::uint32_t b = c.b;
    Frame f = pair_frame(c.a, b);
    const float mb = mobility(b);
    contact<pass>(c, f, v[b], w ? &w[b] : nullptr, mb, r[b]);
    if (pass == Pass::Relax && c.impact_shift != 0.0f) {
      const float ma = mobility(c.a), total = ma + mb;
      x[c.a] += f.n * (c.impact_shift * ma / total);
      x[b] -= f.n * (c.impact_shift * mb / total);
      c.impact_shift = 0.0f;
    }
  }

  template <Pass pass>
  void fixed(Contact& c) const {
    Frame f = static_frame(c.a, c.b);
    Vec3 surface = f.surface_velocity;
    contact<pass>(c, f, surface, nullptr, 0.0f, 1.0f);
    if (pass == Pass::Relax && c.impact_shift != 0.0f) {
      x[c.a] += f.n * c.impact_shift;
      c.impact_shift = 0.0f;
    }
  }

  template <Pass pass>
  void sweep_local(SlabContacts& s) const {
    for (Contact& c : s.pairs) pair<pass>(c);
    for (Contact& c : s.statics) fixed<pass>(c);
  }
};

// Even slabs in parallel, odd slabs in parallel, then serial contacts in slab order.
template <Pass pass>
void sweep(std::vector<SlabContacts>& slabs, const Solver& solver) {
  const int count = static_cast<int>(slabs.size());
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1)
    for (int s = parity; s < count; s += 2) solver.sweep_local<pass>(slabs[s]);
  }
  for (SlabContacts& s : slabs)
    for (Contact& c : s.serial) solver.pair<pass>(c);
}

// Keeps each contact's impulses for the next step, keyed by its generating row and the
// partner's entity (rows move in the next grid rebuild; entities do not).
void store_warm_start(World& world) {
  ContactSet& cs = world.contacts;
  const std::size_t n = world.spheres.size();
  auto entity = world.spheres.entity_index();
  cs.warm_begin.assign(n + 1, 0);
  const int count = static_cast<int>(cs.slabs.size());
  auto each = [](SlabContacts& s, auto&& f) {
    for (Contact& c : s.pairs) f(c);
    for (Contact& c : s.statics) f(c);
    for (Contact& c : s.serial) f(c);
  };
  // A slab's contacts all belong to its own rows, so slabs count and fill independently.
#pragma omp parallel for schedule(dynamic, 1)
  for (int s = 0; s < count; ++s)
    each(cs.slabs[s], [&](Contact& c) {
      if (c.normal_impulse > 0.0f) ++cs.warm_begin[c.a + 1];
    });
  for (std::size_t i = 0; i < n; ++i) cs.warm_begin[i + 1] += cs.warm_begin[i];
  cs.warm.resize(cs.warm_begin[n]);
  std::vector<std::uint32_t> cursor(cs.warm_begin.begin(), cs.warm_begin.end() - 1);
#pragma omp parallel for schedule(dynamic, 1)
  for (int s = 0; s < count; ++s)
    each(cs.slabs[s], [&](Contact& c) {
      if (c.normal_impulse <= 0.0f) return;
      std::uint32_t partner = (c.b & kTagMask) ? c.b : entity[c.b];
      cs.warm[cursor[c.a]++] = {partner, c.normal_impulse, c.friction_impulse};
    });
}

}  // namespace

Access SolverSystem::access() const {
  Access a;
  a.reads = {ColumnId::SphereRadius, ColumnId::SphereInvMass, ColumnId::SphereSleep,
             ColumnId::SphereRows,   ColumnId::Colliders,     ColumnId::Gravity};
  a.writes = {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity,
              ColumnId::Contacts};
  return a;
}

void solve_contacts(World& world) {
  SphereTable& spheres = world.spheres;
  const SolverSettings& settings = world.solver;
  const int substeps = settings.substeps;
  const float h = world.step() / static_cast<float>(substeps);
  // A spring stiffer than half the substep rate is not resolved by the substeps: cap it.
  const float hertz = std::min(settings.contact_hertz, 0.5f / h);
  const ColliderTable& colliders = world.colliders;
  Solver solver{spheres.mut_position().data(),
                spheres.mut_velocity().data(),
                spheres.has_angular() ? spheres.mut_angular_velocity().data() : nullptr,
                spheres.radius().data(),
                spheres.inv_mass().data(),
                spheres.asleep().data(),
                world.pit,
                colliders.a(),
                colliders.b(),
                colliders.velocity_a(),
                colliders.velocity_b(),
                colliders.radius(),
                h,
                1.0f / h,
                make_softness(hertz, settings.damping_ratio, h),
                settings.push_out_speed,
                settings.restitution_threshold};

  std::vector<SlabContacts>& slabs = world.contacts.slabs;
  for (int sub = 0; sub < substeps; ++sub) {
    integrate_velocities(spheres, world.gravity(), h, settings);
    sweep<Pass::WarmStart>(slabs, solver);
    sweep<Pass::Solve>(slabs, solver);
    integrate_positions(spheres, h);
    sweep<Pass::Relax>(slabs, solver);
  }
  store_warm_start(world);
}

}  // namespace ballpit
