#include "systems/substep_control.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/error.h"
#include "engine/thread_share.h"
#include "engine/world.h"

namespace ballpit {

namespace {

// Fewest contacts worth a thread of their own when measuring the deepest overlap.
constexpr std::size_t kContactsPerThread = 65536;

}  // namespace

double contact_penetration_r(const World& world) {
  auto x = world.spheres.position();
  auto r = world.spheres.radius();
  const Pit& pit = world.pit;
  const ColliderTable& colliders = world.colliders;
  // Colliders sit at a + velocity * dt at the end of the step (systems/joint_colliders.h).
  const float dt = world.step();
  auto ca = colliders.a();
  auto cb = colliders.b();
  auto cva = colliders.velocity_a();
  auto cvb = colliders.velocity_b();
  auto cr = colliders.radius();
  const std::size_t rows = x.size();

  auto depth_r = [&](const Contact& c) -> double {
    const std::uint32_t i = c.a;
    if (i >= rows) return 0.0;
    if (c.b & kPlaneTag) {
      const int p = static_cast<int>(c.b & ~kTagMask);
      if (p >= pit.plane_count() || !pit.plane_applies(p, x[i])) return 0.0;
      const float gap = pit.plane_normal(p).dot(x[i]) - pit.plane_offset(p) - r[i];
      return static_cast<double>(-gap) / r[i];
    }
    if (c.b & kColliderTag) {
      const std::uint32_t k = c.b & ~kTagMask;
      if (k >= cr.size()) return 0.0;
      const Vec3 a = ca[k] + cva[k] * dt, b = cb[k] + cvb[k] * dt;
      const float t = closest_segment_parameter(a, b, x[i]);
      const float dist = (x[i] - (a + t * (b - a))).norm();
      return static_cast<double>(r[i] + cr[k] - dist) / r[i];
    }
    const std::uint32_t j = c.b;
    if (j >= rows) return 0.0;
    const float dist = (x[i] - x[j]).norm();
    return static_cast<double>(r[i] + r[j] - dist) / std::min(r[i], r[j]);
  };

  const std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const std::int64_t count = static_cast<std::int64_t>(slabs.size());
  double deepest = 0.0;
  // A team only for many contacts: at 1k spheres 2 threads took 0.064 ms against 0.008 on 1,
  // at 10k 0.096 against 0.081; at 100k 0.63 against 1.13 (profiling/reports/systems.md).
  const TeamSize team(team_for(world.contacts.count(), kContactsPerThread));
  // A max is exact in any order: the result does not depend on the threads.
#pragma omp parallel for schedule(dynamic, 4) reduction(max : deepest)
  for (std::int64_t k = 0; k < count; ++k) {
    const SlabContacts& s = slabs[static_cast<std::size_t>(k)];
    for (const Contact& c : s.pairs) deepest = std::max(deepest, depth_r(c));
    for (const Contact& c : s.statics) deepest = std::max(deepest, depth_r(c));
    for (const Contact& c : s.serial) deepest = std::max(deepest, depth_r(c));
  }
  return deepest;
}

SubstepController::SubstepController(const SubstepControlSettings& s) : settings_(s), calm_needed_(s.calm_steps) {
  if (!(s.tolerance_r > 0.0 && s.tolerance_r <= 1.0))
    throw Error("tolerance must be in (0, 1] (a fraction of the ball radius), got " + std::to_string(s.tolerance_r));
  if (s.min_substeps < 1 || s.max_substeps > 64 || s.min_substeps > s.max_substeps)
    throw Error("substep bounds must satisfy 1 <= min <= max <= 64, got [" + std::to_string(s.min_substeps) + ", " +
                std::to_string(s.max_substeps) + "]");
  if (s.calm_steps < 1) throw Error("calm_steps must be >= 1, got " + std::to_string(s.calm_steps));
}

int SubstepController::next(int substeps, double overlap_r) {
  const SubstepControlSettings& s = settings_;
  const double tolerance = s.tolerance_r;
  const int n = std::clamp(substeps, s.min_substeps, s.max_substeps);
  if (since_lowered_ >= 0 && ++since_lowered_ > calm_needed_) {
    // The last lowering held for a whole calm period: probing may speed up again.
    since_lowered_ = -1;
    calm_needed_ = std::max(s.calm_steps, calm_needed_ / 2);
  }

  if (overlap_r <= kNearFraction * tolerance) {
    if (n == s.min_substeps) return n;
    window_max_ = std::max(window_max_, overlap_r);
    if (++calm_ < calm_needed_) return n;
    // A calm window: the fewest substeps (down to a quarter fewer, and one fewer at least)
    // at which the window's worst overlap, scaled as 1/substeps^2, stays under kLowerFraction x P.
    const int floor = std::max(s.min_substeps, std::min(n - 1, static_cast<int>(std::ceil(kLowerStep * n))));
    int lower = n;
    while (lower > floor) {
      const double ratio = static_cast<double>(n) / static_cast<double>(lower - 1);
      if (window_max_ * ratio * ratio >= kLowerFraction * tolerance) break;
      --lower;
    }
    calm_ = 0;
    window_max_ = 0.0;
    if (lower < n) since_lowered_ = 0;
    return lower;
  }

  int wanted = n + 1;  // near P: one more
  if (overlap_r > tolerance) {
    // Over: as if the overlap went as 1/substeps^2, aim at kLowerFraction x P, at least 1.5x
    // and at most 4x at once.
    const double factor = std::clamp(std::sqrt(overlap_r / (kLowerFraction * tolerance)), 1.5, 4.0);
    wanted = std::max(n + 1, static_cast<int>(std::ceil(n * factor)));
  }
  calm_ = 0;
  window_max_ = 0.0;
  if (since_lowered_ >= 0) {
    // The level just probed failed: wait twice as long before probing below it again.
    calm_needed_ = std::min(kMaxCalmSteps, 2 * calm_needed_);
    since_lowered_ = -1;
  }
  return std::min(wanted, s.max_substeps);
}

Access SubstepControlSystem::access() const {
  Access a;
  a.reads = {ColumnId::SpherePosition, ColumnId::SphereRadius, ColumnId::Colliders};
  a.writes = {ColumnId::Contacts};  // the warm-start cache, scaled to the new substeps (World::set_substeps)
  return a;
}

void SubstepControlSystem::run(World& world) {
  const int used = world.solver.substeps;
  const double overlap = contact_penetration_r(world);
  SubstepControlStats& st = stats_;
  st.substeps_min = st.steps ? std::min(st.substeps_min, used) : used;
  st.substeps_max = st.steps ? std::max(st.substeps_max, used) : used;
  ++st.steps;
  st.substeps_sum += static_cast<std::uint64_t>(used);
  st.max_overlap_r = std::max(st.max_overlap_r, overlap);
  if (overlap > controller_.settings().tolerance_r) ++st.steps_over;
  world.set_substeps(controller_.next(used, overlap));
}

}  // namespace ballpit
