#include "systems/solver.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "engine/packed3.h"
#include "engine/world.h"
#include "systems/integrate.h"

namespace ballpit {

namespace {

// For a solid sphere r^2 / I = 5 / (2 m): how much harder a contact point is to slide than the
// centre is to push.
constexpr float kSphereAngularFactor = 2.5f;

// Sweeps of the joint-collider guard per substep. A sphere wedged between two limbs is pushed
// out of each in turn; a few rounds settle such a wedge (one does not: the second push can
// undo the first).
constexpr int kColliderGuardPasses = 4;

// Overlap (fraction of the smaller radius) beyond which a contact is not warm-started. Its last
// impulse was found for a pair that has since moved deep into each other, the state of a crowd
// spawned inside itself or of a ball wedged under a limb: there, re-applying impulses that
// cancelled each other in the old geometry fed each substep's impulses into the next (speeds
// grew 1.7x per substep, to 48 m/s in the speed-error crowd case and 16 m/s off a 6 m/s limb
// in the 10k pit-character test). A resting pile overlaps by well under a tenth of r. An
// overlap this deep is also no impact unless one move at the pair's speed could have made it
// (see contact()).
constexpr float kWarmStartReach = 0.5f;

enum class Pass { WarmStart, Solve, Relax };

struct Solver {
  Vec3* x;
  Vec3* v;
  Vec3* w;  // null without angular state
  const float* r;
  const float* inv_mass;
  const std::uint8_t* asleep;
  std::uint8_t* pushed;  // rows a contact acted on this substep (see integrate_positions)
  const std::uint8_t* in_pile;  // rows resting on another sphere (see mark_piled_rows)
  Vec3* pseudo;          // push-out velocity of each row this substep (split impulse)
  std::uint8_t* wake_requests;  // sleepers struck hard enough to wake (ContactSet)
  const Pit& pit;
  std::span<const Vec3> ca, cb, cva, cvb;
  std::span<const float> cr;
  float h, inv_h;
  float push_out_rate;
  float push_out_speed;
  float restitution_threshold;
  float wake_speed;
  Vec3 gravity;
  // Time into the step at which joint colliders are posed (unit: s). A collider row holds its
  // pose at the step's start and the velocity that carries it to the animation's pose at the
  // end (systems/joint_colliders.h), so each substep sees it where it is at that moment: a
  // fast limb sweeps the step in substep-sized moves instead of jumping a whole step at once.
  float collider_time = 0.0f;
  // Per row, for this step (sleep does not change inside it): inverse mass, 0 while asleep (a
  // sleeper acts as fixed), and the spin one unit of tangential impulse gives (null without
  // angular state). Looked up, not recomputed, by every contact in every pass.
  const float* mobile_inv_mass = nullptr;
  const float* spin_per_impulse = nullptr;
  // Whether each pair's kept frame (Contact::normal, gap) is that of the current positions.
  // Positions change only in the move and in Relax's impact shifts, so a frame Relax computes
  // serves the next substep's WarmStart and Solve, unless a shift (rare: impacts) moved a sphere
  // after its frame was taken; then, as at a step's start, WarmStart computes them all again.
  bool pair_frames_current = false;
  bool keep_pair_frames = true;  // false: every pass computes its frames (SolverSettings)
  std::atomic<bool>* shifted = nullptr;  // set by any impact shift during Relax

  float mobility(std::uint32_t i) const { return mobile_inv_mass[i]; }

  // Overlapping deeper than kWarmStartReach of the smaller radius.
  static bool beyond_reach(float gap, float ra, float rb) { return gap < -kWarmStartReach * std::min(ra, rb); }

  // The contact frame and gap for a contact: n points from a toward b.
  struct Frame {
    Packed3 n;
    float gap;
    Packed3 surface_velocity;  // of a static partner at the contact (unit: m/s)
  };

  Frame pair_frame(std::uint32_t a, std::uint32_t b) const {
    const Packed3 d = Packed3::load(x[b]) - Packed3::load(x[a]);
    const float dist = norm(d);
    const Packed3 n = dist > 1e-9f ? d / dist : Packed3::of(0.0f, 1.0f, 0.0f);
    return {n, dist - r[a] - r[b], Packed3::zero()};
  }

  Frame static_frame(std::uint32_t a, std::uint32_t b) const {
    if (b & kPlaneTag) {
      int p = static_cast<int>(b & ~kTagMask);
      Vec3 np = pit.plane_normal(p);
      return {Packed3::load(-np), np.dot(x[a]) - pit.plane_offset(p) - r[a], Packed3::zero()};
    }
    std::uint32_t c = b & ~kTagMask;
    const Vec3 ea = ca[c] + collider_time * cva[c], eb = cb[c] + collider_time * cvb[c];
    float t = closest_segment_parameter(ea, eb, x[a]);
    Vec3 q = ea + t * (eb - ea);
    Vec3 d = q - x[a];
    float dist = d.norm();
    Vec3 n = dist > 1e-9f ? Vec3(d / dist) : Vec3(0.0f, -1.0f, 0.0f);
    return {Packed3::load(n), dist - r[a] - cr[c], Packed3::load((1.0f - t) * cva[c] + t * cvb[c])};
  }

  // The partner of a contact as the contact sees it, in registers: a sphere's state, loaded by
  // the caller and stored back after the contact, or a static partner's (surface velocity, no
  // mass, no spin), which nothing the contact does outlives.
  struct Partner {
    Packed3 v;       // velocity (unit: m/s)
    Packed3 w;       // angular velocity, read only when the partner spins (unit: rad/s)
    Packed3 pseudo;  // push-out velocity this substep (unit: m/s)
    float inv_mass;  // 0 for a static partner or a sleeper (unit: 1/kg)
    float radius;    // (unit: m)
    float spin;      // spin per unit of tangential impulse (unit: 1/(kg m), rad/s per N s)
    bool pushed = false;  // Solve: the contact acted on it
  };

  // One contact, one pass: sphere a (its state is loaded and stored here) against partner b.
  // `applied` receives the normal impulse this pass applied (unit: N s). Inlined into its two
  // callers: as a call, passing and spilling its many values cost more than a pile's contact
  // does otherwise.
  template <Pass pass, bool spin_a, bool spin_b>
  [[gnu::always_inline]] void contact(Contact& c, const Frame& f, Partner& b, float approach_accel,
                                      float& applied) const {
    const std::uint32_t a = c.a;
    const float ma = mobility(a), mb = b.inv_mass;
    if (ma + mb == 0.0f) return;
    const bool idle = carries_nothing(c);
    Packed3 friction_impulse = Packed3::load(c.friction_impulse);
    Packed3 va = Packed3::load(v[a]);
    Packed3 wa = spin_a ? Packed3::load(w[a]) : Packed3::zero();
    const float ra = r[a], rb = b.radius;
    const Packed3 n = f.n;
    const float ka = spin_a ? spin_per_impulse[a] : 0.0f;

    auto apply = [&](Packed3 impulse) {
      va -= ma * impulse;
      b.v += mb * impulse;
    };
    auto apply_tangential = [&](Packed3 impulse) {
      apply(impulse);
      const Packed3 torque_axis = cross(n, impulse);
      if constexpr (spin_a) wa -= ka * torque_axis;
      if constexpr (spin_b) b.w -= b.spin * torque_axis;
    };
    auto store_a = [&] {
      va.store(v[a]);
      if constexpr (spin_a) wa.store(w[a]);
    };

    if (pass == Pass::WarmStart) {
      // Too deep to trust (kWarmStartReach): solved from nothing this substep.
      if (beyond_reach(f.gap, ra, rb)) {
        c.normal_impulse = 0.0f;
        c.friction_impulse = Vec3::Zero();
        return;
      }
      friction_impulse -= n * dot(n, friction_impulse);
      friction_impulse.store(c.friction_impulse);
      apply(c.normal_impulse * n);
      apply_tangential(friction_impulse);
      store_a();
      return;
    }

    // Spin adds nothing along the normal of a sphere contact, so vn needs no cross products.
    float vn = dot(b.v - va, n);
    // A speculative contact that will not close this substep, and carries nothing: skip.
    if (idle && f.gap > 0.0f && vn + f.gap * inv_h >= 0.0f) return;
    const float normal_mass = 1.0f / (ma + mb);

    // An impact: restitution when it happens, and the move corrected so the pair ends where
    // the exact bounce leaves it. A pair that will close its gap during the next move must end
    // it closer by (1+e) x that gap (the move carries it apart for the whole substep); a pair
    // that overlapped during the last move (seen by Relax) must end apart by (1+e) x the
    // overlap. Both passes look for impacts: Relax sees what the last move brought together
    // (Newton's cradle in the order the sweep does not favour) and must catch an approach
    // before its speculative constraint turns it into a plain inelastic stop. Only an unloaded
    // contact can be struck: in a loaded one (a pile) the warm start moves velocities around,
    // and reading that as an impact would pump energy into the pile. "Unloaded" means over the
    // whole last step too: inside a pile, Gauss-Seidel leaves a loaded contact momentarily
    // empty, and with few substeps those moments turned into bounces that boiled the pile
    // (pour 10k at 3 substeps: 38 J left at the end instead of 0.003 J).
    // Nor is an overlap deeper than the warm-start reach unless one move at this speed could have
    // made it: that is a crowd's spawn or a jam, whose impulse the warm start just dropped, and
    // bouncing it (and shifting the pair by the overlap) made 3 of 10 random crowds up to
    // 8.6 m/s faster than falling at the default push-out cap (none without). A resting pile never
    // overlaps that deep: the pour at 10k is bit for bit what it was; at 100k a pair in the
    // collapse did, and the pile ends as close (max overlap 0.00097 r, was 0.00133 r).
    float impact = 0.0f;
    if (c.restitution > 0.0f && c.normal_impulse == 0.0f && !c.loaded_last_step &&
        vn < -restitution_threshold && f.gap + vn * h < 0.0f &&
        (f.gap >= vn * h || !beyond_reach(f.gap, ra, rb))) {  // made by one move, or not deep
      // A gap the next move will close is the next Solve's impact (it then corrects that
      // move exactly); Relax must only keep its speculative stop from loading the contact.
      if (pass == Pass::Relax && f.gap > 0.0f) return;
      // Gravity changes vn by `approach_accel` per second (static partners only: two falling
      // spheres share it). The rebound leaves at -e vn(t_contact); what the velocity must be
      // now, for the substep to end as the exact bounce does, depends on when the contact
      // falls within the substep: in the move ahead (Solve, or Relax seeing a gap the next
      // move closes), or in the move just made (Relax seeing an overlap).
      const bool overlapped_in_last_move = pass == Pass::Relax;
      const float t = std::clamp(std::max(f.gap, 0.0f) / -vn, 0.0f, h);
      float target = -c.restitution * vn;
      if (pass == Pass::Solve) target += (1.0f + c.restitution) * approach_accel * (h - t);
      impact = (target - vn) * normal_mass;
      apply(impact * n);
      // The correction assumes the pair moves freely for the rest of the substep; two spheres
      // resting in a pile do not, and shifting them shoves them into their neighbours. Against
      // a plane or a collider it stays: without it a settled pit kept creeping at 8 cm/s and the
      // character kicked balls to 18 m/s (test_character_pushing).
      const bool free_pair = (c.b & kTagMask) || (!in_pile[a] && !in_pile[c.b]);
      if (free_pair)
        c.impact_shift = (1.0f + c.restitution) * (overlapped_in_last_move ? f.gap : std::max(f.gap, 0.0f));
      vn = target;
    }

    // Split impulse: the velocity constraint is rigid (stop the approach, or let a gap close
    // exactly), and overlap is pushed out through pseudo-velocities that move positions this
    // substep and are then forgotten. Push-out therefore never becomes real speed, however
    // many overlaps add up along a chain (a crowd spawned inside itself).
    float bias = 0.0f;
    // Speculative: a gap may close this substep, not more. Not in Relax for a contact that
    // carries load: push-out may have opened a hair's gap under it, and letting the pair fall
    // back into it would drain the impulse that holds the pile up.
    if (f.gap > 0.0f && !(pass == Pass::Relax && c.normal_impulse > 0.0f)) {
      bias = f.gap * inv_h;
    } else if (pass == Pass::Solve) {
      Packed3 pa = Packed3::load(pseudo[a]);
      const float push = std::max(push_out_rate * inv_h * f.gap, -push_out_speed);
      const float pvn = dot(b.pseudo - pa, n);
      const float dp = std::max(-normal_mass * (pvn + push), 0.0f);
      pa -= ma * dp * n;
      b.pseudo += mb * dp * n;
      pa.store(pseudo[a]);
    }
    float delta = -normal_mass * (vn + bias);
    float total = std::max(c.normal_impulse + delta, 0.0f);
    delta = total - c.normal_impulse;
    c.normal_impulse = total;
    apply(delta * n);
    applied = delta + impact;
    if (pass == Pass::Solve && (total > 0.0f || impact > 0.0f)) {
      pushed[a] = 1;
      if (mb > 0.0f) b.pushed = true;
    }

    const float limit = c.friction * (c.normal_impulse + impact);
    if (limit == 0.0f && friction_impulse.is_zero()) {
      store_a();
      return;
    }
    const Packed3 at_a = va + (spin_a ? cross(wa, ra * n) : Packed3::zero());
    const Packed3 at_b = b.v + (spin_b ? cross(b.w, -rb * n) : Packed3::zero());
    const Packed3 vr = at_b - at_a;
    const Packed3 vt = vr - n * dot(n, vr);
    const float tangent_mass = 1.0f / (ma + mb + ka * ra + b.spin * rb);
    const Packed3 old = friction_impulse;
    Packed3 next = old - tangent_mass * vt;
    next -= n * dot(n, next);
    const float len2 = squared_norm(next);
    if (len2 > limit * limit) next *= limit / std::sqrt(len2);
    next.store(c.friction_impulse);
    apply_tangential(next - old);
    store_a();
  }

  static bool carries_nothing(const Contact& c) {
    return c.normal_impulse == 0.0f && c.friction_impulse.isZero(0.0f);
  }

  // The pair's frame for this pass: computed (and kept) where positions may have changed since
  // it was kept, else the kept one, which is bit for bit what computing it would give.
  template <Pass pass>
  Frame frame_for(Contact& c) const {
    if (pass == Pass::Relax || !keep_pair_frames || (pass == Pass::WarmStart && !pair_frames_current)) {
      const Frame f = pair_frame(c.a, c.b);
      f.n.store(c.normal);
      c.gap = f.gap;
      return f;
    }
    return {Packed3::load(c.normal), c.gap, Packed3::zero()};
  }

  template <Pass pass, bool spin>
  [[gnu::always_inline]] void pair(Contact& c) const {
    const std::uint32_t b = c.b;
    Frame f = frame_for<pass>(c);
    if (pass == Pass::WarmStart && carries_nothing(c)) return;
    Partner partner{Packed3::load(v[b]),
                    spin ? Packed3::load(w[b]) : Packed3::zero(),
                    pass == Pass::Solve ? Packed3::load(pseudo[b]) : Packed3::zero(),
                    mobility(b),
                    r[b],
                    spin ? spin_per_impulse[b] : 0.0f};
    float applied = 0.0f;
    contact<pass, spin, spin>(c, f, partner, 0.0f, applied);
    // Stored whatever the contact did: storing an unchanged value changes nothing.
    partner.v.store(v[b]);
    if constexpr (spin) partner.w.store(w[b]);
    if (pass == Pass::Solve) partner.pseudo.store(pseudo[b]);
    if (partner.pushed) pushed[b] = 1;
    // A sleeper acts as fixed while it sleeps; a blow that would change the mover's speed by
    // more than wake_speed wakes it (the sleep system acts on the request after the step).
    if (pass == Pass::Solve && asleep[c.a] != asleep[b]) {
      const std::uint32_t mover = asleep[c.a] ? b : c.a, sleeper = asleep[c.a] ? c.a : b;
      if (applied * inv_mass[mover] > wake_speed) wake_requests[sleeper] = 1;
    }
    if (pass == Pass::Relax && c.impact_shift != 0.0f) {
      const float ma = mobility(c.a), mb = partner.inv_mass, total = ma + mb;
      (Packed3::load(x[c.a]) + f.n * (c.impact_shift * ma / total)).store(x[c.a]);
      (Packed3::load(x[b]) - f.n * (c.impact_shift * mb / total)).store(x[b]);
      c.impact_shift = 0.0f;
      shifted->store(true, std::memory_order_relaxed);
    }
  }

  template <Pass pass, bool spin>
  void fixed(Contact& c) const {
    if (pass == Pass::WarmStart && carries_nothing(c)) return;
    Frame f = static_frame(c.a, c.b);
    // A static partner does not spin, so its radius would only set the warm-start reach, which
    // is then measured in the sphere's own radius.
    Partner partner{f.surface_velocity, Packed3::zero(), Packed3::zero(), 0.0f, r[c.a], 0.0f};
    float applied = 0.0f;
    contact<pass, spin, false>(c, f, partner, -gravity.dot(f.n.vec3()), applied);
    if (pass == Pass::Relax && c.impact_shift != 0.0f) {
      (Packed3::load(x[c.a]) + f.n * c.impact_shift).store(x[c.a]);
      c.impact_shift = 0.0f;
      shifted->store(true, std::memory_order_relaxed);
    }
  }

  template <Pass pass, bool spin>
  void sweep_local(SlabContacts& s) const {
    // Fixed contacts first: the floor's support then travels up a column of pairs (sorted
    // bottom-up, y being the fastest key) within one sweep. And last again when solving:
    // pairs pushed a sphere after its wall did, and the wall must have the last word or a
    // crowd can squeeze a sphere through it.
    for (Contact& c : s.statics) fixed<pass, spin>(c);
    for (Contact& c : s.pairs) pair<pass, spin>(c);
    if (pass == Pass::Solve)
      for (Contact& c : s.statics) fixed<pass, spin>(c);
  }

  // Joint-collider guard, once after the last substep, with the colliders where the step
  // leaves them: a sphere still inside one is moved out to its surface along the contact
  // normal, and its approach along that normal (relative to the surface) removed. In a jam (a
  // hoof pressing a ball into the pile) the contacts cannot all hold, and a collider has
  // infinite mass, so it must win: the spheres' overlap takes the rest, and their push-out
  // spreads it over the next step. Once per step, not per substep: a guard inside the
  // substeps keeps re-creating the approach that the pair impacts then bounce (measured: balls
  // at 14 m/s off a 1 m/s hoof). A slab's statics touch only its own rows.
  void guard_colliders(SlabContacts& s) const {
    for (int pass = 0; pass < kColliderGuardPasses; ++pass) {
      for (const Contact& c : s.statics) {
        if (!(c.b & kColliderTag)) continue;
        const Frame f = static_frame(c.a, c.b);
        if (f.gap >= 0.0f) continue;
        const Vec3 n = f.n.vec3();
        x[c.a] += n * f.gap;  // n points into the collider, gap < 0: outward
        const float approach = (v[c.a] - f.surface_velocity.vec3()).dot(n);
        if (approach > 0.0f) v[c.a] -= approach * n;
      }
    }
  }
};

// Even slabs in parallel, odd slabs in parallel, then serial contacts in slab order. `spin`:
// the spheres have angular state, decided once per pass so the contact loop carries no test.
template <Pass pass, bool spin>
void sweep_with(std::vector<SlabContacts>& slabs, const Solver& solver) {
  const int count = static_cast<int>(slabs.size());
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1)
    for (int s = parity; s < count; s += 2) solver.sweep_local<pass, spin>(slabs[s]);
  }
  for (SlabContacts& s : slabs)
    for (Contact& c : s.serial) solver.pair<pass, spin>(c);
}

template <Pass pass>
void sweep(std::vector<SlabContacts>& slabs, const Solver& solver) {
  if (solver.w) sweep_with<pass, true>(slabs, solver);
  else sweep_with<pass, false>(slabs, solver);
}

// Marks the rows with a sphere-sphere contact that carried load at the end of the last step:
// spheres resting in a pile. Their impacts with each other get no exact-bounce position
// correction (Contact::impact_shift): moving a piled sphere by a correction its neighbours do
// not share makes overlaps, whose push-out and impacts pumped energy into piles (pour 4k at 3
// substeps: 0.66 J left after 10 s with the correction, 0.0004 J without). Parity sweeps as
// the solver's, so no two threads write one row.
void mark_piled_rows(std::vector<SlabContacts>& slabs, std::vector<std::uint8_t>& in_pile) {
  auto mark = [&](const std::vector<Contact>& contacts) {
    for (const Contact& c : contacts)
      if (c.loaded_last_step) in_pile[c.a] = in_pile[c.b] = 1;
  };
  const int count = static_cast<int>(slabs.size());
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1)
    for (int s = parity; s < count; s += 2) mark(slabs[s].pairs);
  }
  for (const SlabContacts& s : slabs) mark(s.serial);
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
      if (!(c.normal_impulse > 0.0f)) return;  // the counting pass's test exactly (NaN too)
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
  const ColliderTable& colliders = world.colliders;
  Solver solver{spheres.mut_position().data(),
                spheres.mut_velocity().data(),
                spheres.has_angular() ? spheres.mut_angular_velocity().data() : nullptr,
                spheres.radius().data(),
                spheres.inv_mass().data(),
                spheres.asleep().data(),
                nullptr,
                nullptr,
                nullptr,
                nullptr,
                world.pit,
                colliders.a(),
                colliders.b(),
                colliders.velocity_a(),
                colliders.velocity_b(),
                colliders.radius(),
                h,
                1.0f / h,
                settings.push_out_rate,
                settings.push_out_speed,
                settings.restitution_threshold,
                settings.wake_speed,
                world.gravity()};

  std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const std::int64_t rows = static_cast<std::int64_t>(spheres.size());
  std::vector<float> mobile_inv_mass(spheres.size()), spin_per_impulse(solver.w ? spheres.size() : 0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < rows; ++i) {
    mobile_inv_mass[i] = solver.asleep[i] ? 0.0f : solver.inv_mass[i];
    if (solver.w) spin_per_impulse[i] = kSphereAngularFactor * mobile_inv_mass[i] / solver.r[i];
  }
  solver.mobile_inv_mass = mobile_inv_mass.data();
  solver.spin_per_impulse = solver.w ? spin_per_impulse.data() : nullptr;
  std::vector<std::uint8_t> pushed(spheres.size());
  solver.pushed = pushed.data();
  std::vector<std::uint8_t> in_pile(spheres.size());
  mark_piled_rows(slabs, in_pile);
  solver.in_pile = in_pile.data();
  std::vector<Vec3> pseudo(spheres.size());
  solver.pseudo = pseudo.data();
  world.contacts.wake_requests.assign(spheres.size(), 0);
  solver.wake_requests = world.contacts.wake_requests.data();
  std::atomic<bool> shifted{false};
  solver.shifted = &shifted;
  solver.keep_pair_frames = settings.keep_pair_frames;
  for (int sub = 0; sub < substeps; ++sub) {
    std::fill(pushed.begin(), pushed.end(), std::uint8_t{0});
    std::fill(pseudo.begin(), pseudo.end(), Vec3::Zero());
    integrate_velocities(spheres, world.gravity(), h, settings);
    solver.collider_time = static_cast<float>(sub) * h;  // colliders where the substep starts
    sweep<Pass::WarmStart>(slabs, solver);
    sweep<Pass::Solve>(slabs, solver);
    integrate_positions(spheres, h, world.gravity(), pushed, pseudo);
    solver.collider_time = static_cast<float>(sub + 1) * h;  // and where it ends, as the spheres now are
    shifted.store(false, std::memory_order_relaxed);
    sweep<Pass::Relax>(slabs, solver);
    solver.pair_frames_current = !shifted.load(std::memory_order_relaxed);
  }
  if (colliders.size() > 0) {  // colliders at the step's end (collider_time = dt)
    const int count = static_cast<int>(slabs.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (int k = 0; k < count; ++k) solver.guard_colliders(slabs[k]);
  }
  store_warm_start(world);
}

}  // namespace ballpit
