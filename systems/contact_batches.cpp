#include "systems/contact_batches.h"

#include <algorithm>
#include <bit>

#include "engine/list_capacity.h"
#include "systems/batch_kernels.h"
#include "systems/solver_bodies.h"

namespace ballpit {

namespace {

// Batches open at once. A contact that finds no open batch after the last one holding either of
// its spheres opens a new one, and when kOpenBatches are open the oldest is closed, full or not.
// More open batches fill more lanes but spread each batch over more of the list.
constexpr std::size_t kOpenBatches = 32;

// How many batches past the newest one packing asks the cache for.
constexpr std::size_t kPrefetchBatches = 2;

// How many contacts ahead of the one being packed each list is fetched into the cache.
constexpr std::uint32_t kPrefetchContacts = 8;

// Batches in index order; last[row] is stamp + one past the index of the latest batch holding
// the row (less than stamp: none in this packing). A contact joins the earliest open batch after
// every batch that already holds one of its awake spheres, so each awake sphere meets its
// contacts in list order and no batch holds it twice. A sleeper is no such link: every pass
// leaves its body as it was (its mobility, 0, scales every change to it to nothing, and its
// zeroed velocity and spin stay +0), so the balls resting on it do not wait for each other
// through it, a batch may hold it in several lanes, each storing the same body back, and its
// row in `last` is never read or written (the same state hashes either way).
class Window {
 public:
  Window(BatchList& out, const PackInput& in)
      : out_(out), last_(in.last_batch), stamp_(in.stamp), awake_rows_(in.awake_rows) {}

  // The lane where the contact of sphere rows a and b (b == a: a plane) goes, in its batch.
  struct Lane {
    ContactBatch& batch;
    int lane;
  };
  Lane add(std::uint32_t a, std::uint32_t b) {
    const std::uint32_t after =
        std::max({last_of(a), last_of(b), stamp_ + static_cast<std::uint32_t>(first_free_)});
    std::size_t k = after - stamp_;
    while (k < lanes_.size() && lanes_[k] == kBatchLanes) ++k;
    if (k == lanes_.size()) {
      if (k - first_open_ == kOpenBatches) first_free_ = std::max(first_free_, ++first_open_);  // the oldest closes
      open_new();
    }
    ContactBatch& batch = out_[k];
    const int lane = lanes_[k]++;  // lanes fill in order
    batch.used |= 1u << lane;
    while (first_free_ < lanes_.size() && lanes_[first_free_] == kBatchLanes) ++first_free_;
    const std::uint32_t held = stamp_ + static_cast<std::uint32_t>(k + 1);
    if (a < awake_rows_) last_[a] = held;
    if (b < awake_rows_) last_[b] = held;
    return {batch, lane};
  }

 private:
  std::uint32_t last_of(std::uint32_t row) const { return row < awake_rows_ ? last_[row] : 0; }

  void open_new() {
    ContactBatch& batch = out_.emplace_back();
    batch.used = batch.loaded_last_step = batch.free_pair = 0;
    lanes_.push_back(0);
    // The list keeps its memory from step to step, so a new batch's lines are last step's, long
    // gone from the near caches, and its first store waited on them: ask for a batch a few
    // ahead, never past the capacity (that memory is not the list's).
    const std::size_t ahead = out_.size() + kPrefetchBatches;
    if (ahead < out_.capacity())
      for (std::size_t line = 0; line < sizeof(ContactBatch); line += 64)
        __builtin_prefetch(reinterpret_cast<const char*>(out_.data() + ahead) + line, 1);
  }

  BatchList& out_;
  std::vector<std::uint32_t>& last_;
  const std::uint32_t stamp_;
  const std::uint32_t awake_rows_;
  // Lanes taken in each batch, beside the batches: the search for a batch with room reads these
  // bytes, not a line of each 1 KB batch (that search was a fifth of the packing).
  std::vector<std::uint8_t> lanes_;
  std::size_t first_open_ = 0;  // batches before it are closed
  std::size_t first_free_ = 0;  // no open batch before it has a free lane
};

// What every contact brings to its lane: rows, impulses, material, flags.
void fill(ContactBatch& batch, int lane, const Contact& c, float reach) {
  batch.a[lane] = c.a;
  batch.b[lane] = c.b;
  batch.normal_impulse[lane] = c.normal_impulse;
  batch.fx[lane] = c.friction_impulse.x();
  batch.fy[lane] = c.friction_impulse.y();
  batch.fz[lane] = c.friction_impulse.z();
  batch.friction[lane] = c.friction;
  batch.restitution[lane] = c.restitution;
  batch.reach[lane] = reach;
  batch.impact_shift[lane] = 0.0f;  // no impact yet this step
  if (c.loaded_last_step()) batch.loaded_last_step |= 1u << lane;
}

void start(ContactLists lists, BatchList& out) {
  std::size_t contacts = 0;
  for (const std::vector<Contact>* list : lists) contacts += list->size();
  // Room for 90% full batches without growing: growing copies every batch made so far.
  const std::size_t room = contacts * 10 / (9 * kBatchLanes) + kOpenBatches;
  // Last step's batches, or this one's room if more: capacity from the pour's peak goes back.
  release_excess_capacity(out, std::max(out.size(), room));
  out.clear();
  out.reserve(room);
}

// The lanes no contact took: immobile padding bodies with a finite frame and nothing to apply.
void pad_empty_lanes(BatchList& out, std::uint32_t pad_rows) {
  for (ContactBatch& batch : out)
    for (int lane = std::countr_one(batch.used); lane < kBatchLanes; ++lane) {
      batch.a[lane] = SolverBodies::pad_a(pad_rows, lane);
      batch.b[lane] = SolverBodies::pad_b(pad_rows, lane);
      batch.nx[lane] = batch.nz[lane] = 0.0f;
      batch.ny[lane] = batch.gap[lane] = 1.0f;  // in a plane batch the offset: its padding lies 1e6 m from it
      batch.normal_impulse[lane] = 0.0f;
      batch.fx[lane] = batch.fy[lane] = batch.fz[lane] = 0.0f;
      batch.friction[lane] = batch.restitution[lane] = batch.reach[lane] = batch.impact_shift[lane] = 0.0f;
    }
}

// Calls visit(list, index) for the contacts of all lists, one from each list in turn. Up to
// eight lists are read side by side, more streams than the hardware's prefetch kept up with:
// reading a contact was the slowest load of the packing.
template <class Visit>
void in_turn(ContactLists lists, Visit&& visit) {
  std::size_t longest = 0;
  for (const std::vector<Contact>* list : lists) longest = std::max(longest, list->size());
  for (std::uint32_t i = 0; i < longest; ++i)
    for (std::size_t l = 0; l < lists.size(); ++l) {
      const std::vector<Contact>& list = *lists[l];
      if (i >= list.size()) continue;
      if (i + kPrefetchContacts < list.size()) __builtin_prefetch(list.data() + i + kPrefetchContacts);
      visit(l, i);
    }
}

}  // namespace

void pack_pairs(ContactLists lists, const PackInput& in, BatchList& out) {
  start(lists, out);
  Window window(out, in);
  in_turn(lists, [&](std::size_t l, std::uint32_t i) {
    const Contact& c = (*lists[l])[i];
    const Window::Lane slot = window.add(c.a, c.b);
    fill(slot.batch, slot.lane, c, -kWarmStartReach * std::min(in.radius[c.a], in.radius[c.b]));
    if (!in.in_pile[c.a] && !in.in_pile[c.b]) slot.batch.free_pair |= 1u << slot.lane;
  });
  pad_empty_lanes(out, in.pad_rows);
}

void pack_planes(ContactLists lists, const PackInput& in, BatchList& out) {
  start(lists, out);
  Window window(out, in);
  in_turn(lists, [&](std::size_t l, std::uint32_t i) {
    const Contact& c = (*lists[l])[i];
    if (!(c.b & kPlaneTag)) return;
    const Window::Lane slot = window.add(c.a, c.a);
    // A static partner's radius would only set the warm-start reach, which is then measured in
    // the sphere's own radius.
    fill(slot.batch, slot.lane, c, -kWarmStartReach * in.radius[c.a]);
    const int plane = static_cast<int>(c.b & ~kTagMask);
    const Vec3 n = -in.pit.plane_normal(plane);  // from the sphere into the plane
    slot.batch.nx[slot.lane] = n.x();
    slot.batch.ny[slot.lane] = n.y();
    slot.batch.nz[slot.lane] = n.z();
    slot.batch.plane_offset[slot.lane] = in.pit.plane_offset(plane);
    if (!in.in_pile[c.a]) slot.batch.free_pair |= 1u << slot.lane;  // else the plane gives it no impact
  });
  pad_empty_lanes(out, in.pad_rows);
}

}  // namespace ballpit
