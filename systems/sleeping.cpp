#include "systems/sleeping.h"

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/thread_share.h"
#include "engine/world.h"

namespace ballpit {

namespace {

// Rows (the sleep update) and contacts (the wake check) worth a thread of their own. Both loops
// spend a few nanoseconds an item, and with passive waits a second thread costs tens of
// microseconds to wake (bench_sleeping, packed pits, ms at 1 / 2 threads: the sleep update
// 0.29 / 0.37 at 100k and 2.9 / 1.7 at 1M; the wake check 0.027 / 0.068 at 10k, 29k contacts,
// and 0.39 / 0.27 at 100k, 298k contacts).
constexpr std::size_t kRowsPerThread = 131072;
constexpr std::size_t kContactsPerThread = 65536;

// Several slabs may wake the same sleeper at once; every write stores the same values, so the
// outcome is deterministic, and atomic_ref keeps it free of data races.
void wake_row(std::uint8_t& asleep, float& still) {
  std::atomic_ref<std::uint8_t>(asleep).store(0, std::memory_order_relaxed);
  std::atomic_ref<float>(still).store(0.0f, std::memory_order_relaxed);
}

// Piles that rest on each other: spheres joined by a contact that carried load at the end of
// this step (the warm-start cache, which keeps sleepers' pairs too), found by union-find. The
// root of each row's pile is its lowest row, whatever order the links come in.
class Piles {
 public:
  explicit Piles(const World& world) : parent_(world.spheres.size()) {
    for (std::uint32_t i = 0; i < parent_.size(); ++i) parent_[i] = i;
    const ContactSet& cs = world.contacts;
    if (cs.warm_begin.size() != parent_.size() + 1) return;  // no cache yet: every sphere alone
    for (std::uint32_t i = 0; i < parent_.size(); ++i)
      for (std::uint32_t k = cs.warm_begin[i]; k < cs.warm_begin[i + 1]; ++k) {
        const std::uint32_t partner = cs.warm[k].partner;
        if (partner & kTagMask) continue;  // planes and colliders join nothing
        const std::uint32_t j = world.spheres.row_of_index(partner);
        if (j != SphereTable::kNoRow) join(i, j);
      }
    for (std::uint32_t i = 0; i < parent_.size(); ++i) parent_[i] = root(i);
  }

  std::uint32_t of(std::uint32_t row) const { return parent_[row]; }

 private:
  std::uint32_t root(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = root(a);
    b = root(b);
    if (a < b) parent_[b] = a;
    else if (b < a) parent_[a] = b;
  }

  std::vector<std::uint32_t> parent_;
};

// What each pile's awake members say, by pile root: kRestless, one has not been still for
// sleep_time; kMoving, one moved this step or was just woken (its still time is 0).
constexpr std::uint8_t kRestless = 1, kMoving = 2;

std::vector<std::uint8_t> pile_states(const Piles& piles, std::span<const std::uint8_t> asleep,
                                      std::span<const float> still, float sleep_time) {
  std::vector<std::uint8_t> state(asleep.size(), 0);
  for (std::uint32_t i = 0; i < asleep.size(); ++i) {
    if (asleep[i]) continue;
    std::uint8_t& pile = state[piles.of(i)];
    if (still[i] < sleep_time) pile |= kRestless;
    if (still[i] == 0.0f) pile |= kMoving;
  }
  return state;
}

}  // namespace

Access WakeSystem::access() const {
  // What waking reads, and what the narrowphase reads and writes to find the contacts again.
  Access a = NarrowphaseSystem().access();
  a.writes.add(ColumnId::SphereSleep);
  return a;
}

void WakeSystem::run(World& world) {
  if (wake_approached(world)) find_contacts(world, scratch_);
}

Access SleepSystem::access() const {
  Access a;
  a.reads = {ColumnId::SphereRadius, ColumnId::SphereRows, ColumnId::Contacts};
  a.writes = {ColumnId::SphereSleep, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity};
  return a;
}

bool wake_approached(World& world) {
  const ContactSet& found = world.contacts;
  const TeamSize team(team_for(found.count(), kContactsPerThread));
  SphereTable& spheres = world.spheres;
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  auto v = spheres.velocity();
  auto cva = world.colliders.velocity_a();
  auto cvb = world.colliders.velocity_b();
  const float wake2 = world.solver.wake_speed * world.solver.wake_speed;
  std::vector<SlabContacts>& slabs = world.contacts.slabs;
  const int count = static_cast<int>(slabs.size());
  std::atomic<bool> any_woken = false;
  auto wake = [&](std::uint32_t row) {
    wake_row(asleep[row], still[row]);
    any_woken.store(true, std::memory_order_relaxed);
  };

  auto check = [&](const Contact& c) {
    if (c.b & kColliderTag) {
      std::uint32_t k = c.b & ~kTagMask;
      if (k < cva.size() && asleep[c.a] && std::max(cva[k].squaredNorm(), cvb[k].squaredNorm()) > wake2)
        wake(c.a);
      return;
    }
    if (c.b & kTagMask) return;
    const bool sa = asleep[c.a], sb = asleep[c.b];
    if (sa == sb) return;
    std::uint32_t sleeper = sa ? c.a : c.b, mover = sa ? c.b : c.a;
    if (v[mover].squaredNorm() > wake2) wake(sleeper);
  };
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < count; ++k) {
    for (const Contact& c : slabs[k].pairs) check(c);
    for (const Contact& c : slabs[k].statics) check(c);
    for (const Contact& c : slabs[k].serial) check(c);
  }
  if (!any_woken) return false;
  // The pile of a woken sphere (or of one that moved) wakes with it, before the step: woken
  // alone, the sphere would be driven into neighbours that cannot yield (a ball dropped 0.5 m on
  // a sleeping pile of 1,000 left it overlapping by 0.5 r), and they would wake a few at a time.
  const Piles piles(world);
  const std::vector<std::uint8_t> state = pile_states(piles, asleep, still, world.solver.sleep_time);
  const std::int64_t n = static_cast<std::int64_t>(spheres.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i)
    if (asleep[i] && (state[piles.of(static_cast<std::uint32_t>(i))] & kMoving)) wake_row(asleep[i], still[i]);
  return true;
}

void update_sleep(World& world) {
  const TeamSize team(team_for(world.spheres.size(), kRowsPerThread));
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
  // The clock, and what it says about whether any pile may change (below).
  bool ready = false, moving = false, sleeper = false;
#pragma omp parallel for schedule(static) reduction(|| : ready, moving, sleeper)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i]) {
      sleeper = true;
      continue;
    }
    float spin = angular ? w[i].squaredNorm() * r[i] * r[i] : 0.0f;
    if (v[i].squaredNorm() < sleep2 && spin < sleep2) still[i] += dt;
    else still[i] = 0.0f;
    ready = ready || still[i] >= s.sleep_time;
    moving = moving || still[i] == 0.0f;
  }

  // A pile sleeps and wakes as one. A sphere asleep alone in a pile is a fixed body inside it:
  // it stops passing on the weight it carries, and the spheres around it are warm-started with
  // loads it no longer shares. A settled 10k pour slept that way part by part and never came
  // to rest again (after 1,200 steps 0.25 J, top speed 0.56 m/s and overlaps of 0.12 r, against
  // 3e-6 J, 0.002 m/s and 0.0005 r with sleeping off); woken parts woke their neighbours in
  // waves. So a pile sleeps once every member has been still for sleep_time, and wakes whole
  // when a member moves (or is woken). A slow member that joins a sleeping pile, a ball that
  // comes to lean on it, does not wake it: it sleeps when its own still time is up.
  // The piles (a union-find over every loaded pair: 0.27 ms a step for a settled 10k pile,
  // bench_sleeping) are built only when one may change: a pile falls asleep only if an awake
  // member is ready to (still for sleep_time), and wakes only if a member is awake and moving
  // (its still time is 0) while some sphere sleeps. A pit asleep whole skips them.
  if (!ready && !(sleeper && moving)) return;
  const Piles piles(world);
  const std::vector<std::uint8_t> pile_state = pile_states(piles, asleep, still, s.sleep_time);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const std::uint8_t state = pile_state[piles.of(static_cast<std::uint32_t>(i))];
    if (!asleep[i] && !(state & kRestless)) {
      asleep[i] = 1;
      v[i].setZero();
      if (angular) w[i].setZero();
    } else if (asleep[i] && (state & kMoving)) {
      asleep[i] = 0;  // its pile woke
      still[i] = 0.0f;
    }
  }
}

}  // namespace ballpit
