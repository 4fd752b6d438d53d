// One pass of one contact, written once for any lane type: sixteen sphere pairs at once
// (T = Lanes, systems/batch_kernels_impl.h) or one contact at a time (T = float: pit planes,
// joint colliders, pairs that span slabs; systems/solver.cpp). The passes and why each rule is
// there: systems/solver.h. The kernel reads and writes a ContactState; the callers load it from
// and store it to memory, so the kernel is the physics and nothing else.
//
// Lanes never branch apart: a rule that applies to some lanes is computed for all and selected,
// and a lane that must change nothing (both bodies immobile, or an impact the Relax pass leaves
// to the next move) runs with zero effective mass, so every impulse it computes is zero.
//
// Like systems/lanes.h, this file lives in the namespace of the instruction set it is compiled
// for.
#pragma once

#include "systems/batch_kernels.h"
#include "systems/lanes.h"

namespace ballpit::BALLPIT_LANES_TARGET {

// f in every lane (T{} is zero for floats and lanes alike).
template <class T>
inline T broadcast(float f) { return T{} + f; }

template <class T>
struct V3 {
  T x, y, z;
};

template <class T>
inline V3<T> operator+(const V3<T>& a, const V3<T>& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class T>
inline V3<T> operator-(const V3<T>& a, const V3<T>& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T>
inline V3<T> operator*(const T& s, const V3<T>& a) { return {s * a.x, s * a.y, s * a.z}; }
// x + (y + z), as Eigen sums three products.
template <class T>
inline T dot(const V3<T>& a, const V3<T>& b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
template <class T>
inline V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T, class M>
inline V3<T> select(M m, const V3<T>& a, const V3<T>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

using Pass = ContactPass;

// A contact as one pass sees it (per lane for T = Lanes).
template <class T, class M>
struct ContactState {
  V3<T> n;        // unit normal from sphere a toward its partner
  T gap;          // (unit: m), negative when overlapping
  T reach;        // -kWarmStartReach x the smaller radius: deeper is beyond warm starting (m)
  V3<T> va, sa;   // sphere a: velocity, spin as r w (unit: m/s)
  T ma;           // sphere a's inverse mass this step, 0 asleep (unit: 1/kg)
  V3<T> vb, sb;   // the partner's; sb unused for a static partner
  T mb;           // 0 for a static partner
  V3<T> pa, pb;   // push-out velocities, Solve only (unit: m/s)
  T pushed_a, pushed_b;  // Solve sets 1 where a contact acted on the body this substep
  T normal_impulse;      // accumulated over the substep (unit: N s)
  V3<T> friction_impulse;
  T friction, restitution;
  T impact_shift;        // (1+e) x gap of this substep's impact, applied after Relax (m)
  M loaded_last_step;    // carried load at the end of the last step: never an impact
  M free_pair;           // no sphere of it rests in a pile: an impact may shift it, and strike a static partner
  T applied;             // out: normal impulse this pass applied, impacts included (N s)
  T impact;              // out: impact impulse this pass applied (N s)
};

template <class T, class M>
struct ContactKernel {
  using State = ContactState<T, M>;

  // Applies an impulse along the contact: -J to sphere a, +J to the partner.
  static void apply(State& c, const V3<T>& j) {
    c.va = c.va - c.ma * j;
    c.vb = c.vb + c.mb * j;
  }

  // A tangential impulse also spins both: the torque arm is r n on a and -r n on the partner,
  // and both give -(n x J) as the change of r w (over m / kSphereSpinFactor).
  template <bool spin, bool spin_b>
  static void apply_tangential(State& c, const V3<T>& j) {
    apply(c, j);
    if constexpr (spin) {
      const V3<T> torque_axis = cross(c.n, j);
      c.sa = c.sa - (broadcast<T>(kSphereSpinFactor) * c.ma) * torque_axis;
      if constexpr (spin_b) c.sb = c.sb - (broadcast<T>(kSphereSpinFactor) * c.mb) * torque_axis;
    }
  }

  // Warm start: re-applies last substep's impulses, the friction impulse first turned into the
  // current tangent plane; an overlap beyond reach starts from nothing.
  template <bool spin, bool spin_b>
  static void warm_start(State& c) {
    const M live = (c.ma + c.mb) > broadcast<T>(0.0f);
    const M drop = live & (c.gap < c.reach);
    const V3<T> f = c.friction_impulse - dot(c.n, c.friction_impulse) * c.n;
    c.normal_impulse = select(drop, broadcast<T>(0.0f), c.normal_impulse);
    c.friction_impulse = select(live, select(drop, V3<T>{}, f), c.friction_impulse);
    apply(c, c.normal_impulse * c.n);
    apply_tangential<spin, spin_b>(c, c.friction_impulse);
  }

  // Solve and Relax. `static_partner`: a pit plane or joint collider, which gravity does not
  // move (approach_accel: how fast gravity closes the gap, m/s^2).
  template <Pass pass, bool spin, bool static_partner>
  static void solve(State& c, T approach_accel, const PassParams& p) {
    constexpr bool spin_b = spin && !static_partner;
    const T zero = broadcast<T>(0.0f), one = broadcast<T>(1.0f);
    const M live = (c.ma + c.mb) > zero;
    // Spin adds nothing along the normal of a sphere contact, so vn needs no cross products.
    T vn = dot(c.vb - c.va, c.n);

    // An impact: restitution when it happens, and the move corrected so the pair ends where the
    // exact bounce leaves it (systems/solver.h). Only an unloaded contact can be struck, and an
    // overlap beyond reach only if one move at this speed could have made it (a crowd's spawn is
    // no impact).
    const T h = broadcast<T>(p.h);
    const M unloaded = mask_not(c.loaded_last_step), beyond_reach = mask_not(c.gap < c.reach);
    M strike = (c.restitution > zero) & (c.normal_impulse == zero) & unloaded &
               (vn < broadcast<T>(-p.restitution_threshold)) & (c.gap + vn * h < zero) &
               ((c.gap >= vn * h) | beyond_reach);
    // Nor does a static partner (pit plane, joint collider) strike a sphere resting in a pile:
    // the warm start re-applies the pile's load to it each substep, which reads as an approach.
    // A sphere under a crowd got 16 m/s of it against the floor, whose impulse Relax had let
    // go, and was bounced out at 10 m/s at the default cap (1,000 balls spawned in a tenth of
    // their room, seed 28). A limb crushing a pile into the floor bounced such approaches too:
    // balls left a 9 m/s capsule at 29 m/s, and the 100k pit-character's fastest ball at 15.8
    // (tests/test_character_pushing.cpp).
    if constexpr (static_partner) strike = strike & c.free_pair;
    M keep = live;
    if constexpr (pass == Pass::Relax) {
      // A gap the next move will close is the next Solve's impact; Relax leaves it alone.
      keep = keep & mask_not(strike & (c.gap > zero));
    }
    strike = strike & keep;
    const T normal_mass = select(keep, one / (c.ma + c.mb), zero);

    c.impact = zero;
    if (any(strike)) {
      T target = -c.restitution * vn;
      if constexpr (pass == Pass::Solve && static_partner) {
        // Gravity changes vn until the contact: where the contact falls within the substep
        // decides what the velocity must be now for the substep to end as the bounce does.
        const T t = min(max(max(c.gap, zero) / -vn, zero), h);
        target = target + (one + c.restitution) * approach_accel * (h - t);
      }
      c.impact = select(strike, (target - vn) * normal_mass, zero);
      apply(c, c.impact * c.n);
      const T overlap = pass == Pass::Relax ? c.gap : max(c.gap, zero);
      c.impact_shift = select(strike & c.free_pair, (one + c.restitution) * overlap, c.impact_shift);
      vn = select(strike, target, vn);
    }

    // Split impulse: the velocity constraint is rigid (stop the approach, or let a gap close
    // exactly) and overlap is pushed out by pseudo-velocities that move the spheres this substep
    // and are then forgotten, so push-out never becomes speed. Relax lets no loaded contact fall
    // back into a hair's gap that push-out opened under it.
    M speculative = c.gap > zero;
    if constexpr (pass == Pass::Relax) speculative = speculative & mask_not(c.normal_impulse > zero);
    const T bias = select(speculative, c.gap * broadcast<T>(p.inv_h), zero);
    if constexpr (pass == Pass::Solve) {
      const T push = max(broadcast<T>(p.push_rate) * c.gap, broadcast<T>(-p.push_out_speed));
      const T pvn = dot(c.pb - c.pa, c.n);
      const T dp = select(c.gap > zero, zero, max(-normal_mass * (pvn + push), zero));
      c.pa = c.pa - (c.ma * dp) * c.n;
      c.pb = c.pb + (c.mb * dp) * c.n;
    }
    const T total = max(c.normal_impulse + -normal_mass * (vn + bias), zero);
    const T delta = total - c.normal_impulse;
    c.normal_impulse = select(keep, total, c.normal_impulse);
    apply(c, delta * c.n);
    c.applied = delta + c.impact;
    if constexpr (pass == Pass::Solve) {
      const M acted = keep & ((total > zero) | (c.impact > zero));
      c.pushed_a = select(acted, one, c.pushed_a);
      c.pushed_b = select(acted & (c.mb > zero), one, c.pushed_b);
    }

    // Coulomb friction on the slip of the contact points, clamped to the cone.
    const T limit = c.friction * (c.normal_impulse + c.impact);
    V3<T> slip = c.vb - c.va;
    if constexpr (spin) slip = slip - cross(c.sa, c.n);
    if constexpr (spin_b) slip = slip - cross(c.sb, c.n);
    const V3<T> tangential = slip - dot(c.n, slip) * c.n;
    T inertia = c.ma + c.mb;
    if constexpr (spin) inertia = inertia + broadcast<T>(kSphereSpinFactor) * c.ma;
    if constexpr (spin_b) inertia = inertia + broadcast<T>(kSphereSpinFactor) * c.mb;
    const T tangent_mass = select(keep, one / inertia, zero);
    const V3<T> old = c.friction_impulse;
    V3<T> next = old - tangent_mass * tangential;
    next = next - dot(c.n, next) * c.n;
    const T len2 = dot(next, next);
    const M over = len2 > limit * limit;
    if (any(over)) next = select(over, (limit / sqrt(len2)) * next, next);
    c.friction_impulse = select(keep, next, old);
    apply_tangential<spin, spin_b>(c, c.friction_impulse - old);

    // Spinning friction, once a substep (in Relax: Solve meets a static partner twice): a
    // torque of at most mu N kTwistArmFraction r about the normal changes r w . n by at most
    // mu N kTwistArmFraction kSphereSpinFactor / m (the radius cancels). Between spheres the
    // arms would need both radii, which the passes do not all load; a ball spinning about a line
    // of centres is rare, and its other contacts brake it.
    if constexpr (spin && static_partner && pass == Pass::Relax) {
      const T twist = dot(c.sa, c.n);
      const T most = broadcast<T>(kTwistArmFraction * kSphereSpinFactor) * c.friction * c.normal_impulse * c.ma;
      c.sa = c.sa - max(min(twist, most), -most) * c.n;
    }
  }
};

// The frame of a sphere pair from its centres and radii: n from a to b, gap (m).
template <class T>
inline void pair_frame(const V3<T>& xa, const V3<T>& xb, T ra, T rb, V3<T>& n, T& gap) {
  const V3<T> d = xb - xa;
  const T dist = sqrt(dot(d, d));
  const auto apart = dist > broadcast<T>(1e-9f);
  n = {select(apart, d.x / dist, broadcast<T>(0.0f)), select(apart, d.y / dist, broadcast<T>(1.0f)), select(apart, d.z / dist, broadcast<T>(0.0f))};
  gap = dist - ra - rb;
}

}  // namespace ballpit::BALLPIT_LANES_TARGET
