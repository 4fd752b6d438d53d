// A slab's sphere pairs, and its spheres' contacts with the pit planes, cut into batches of
// sixteen that share no sphere, stored a column per field, so the solver runs sixteen contacts at
// once (systems/batch_kernels.h) and moves each field in and out of its lanes with one load and
// one store. Joint colliders stay one at a time: few spheres touch them.
//
// Batching keeps Gauss-Seidel's order exactly: a contact joins the earliest batch after every
// batch that holds one of its spheres, so each sphere meets its contacts in list order, and
// solving the batches one after another gives bit for bit what solving the list one contact at a
// time gives. The order matters: the lists are sorted bottom-up, so the floor's support climbs a
// column of pairs within one sweep, and a crowd spawned inside itself separates calmly. Batches
// that ignored it (a pair joined any batch holding neither sphere, 99.7% of lanes filled) left
// a ball squeezed between the floor and a jam with the floor's impulse a substep behind the
// pairs': it left at 3-5 m/s more than the push-out cap and gravity allow, in 3 of 10 spawns of
// the crowd hard case (none in list order).
//
// One slab's list is a chain: its contacts depend on each other about 500 deep in a settled pile
// of 100k, so its batches fill only 59% of their lanes. Slabs of one parity share no sphere,
// so several of them are packed into one stream (ContactLists), which fills 97%. Batches open
// in a window of kOpenBatches, which keeps a batch's rows close in memory; lanes left empty point
// at immobile padding bodies (SolverBodies::kPadRows) and change nothing.
//
// Batching depends only on the slab's list, so the solver's result is the same for any number
// of threads.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/aligned_vector.h"
#include "engine/contact_set.h"
#include "engine/settings.h"
#include "systems/contact_batch.h"

namespace ballpit {

// One stream of batches, solved in order.
using BatchList = Column<ContactBatch>;

// What packing needs besides the contacts: `radius` per row (m); `in_pile` marks the rows resting
// on another sphere (ContactSet::piled); `pad_rows` is the first padding body; rows from
// `awake_rows` on sleep (systems/sleep_regions.h: RowSpans). `last_batch` is
// scratch with one entry per row, zeroed once per step and shared by every packing in it, each
// with a `stamp` above every value the packings before it wrote (kStampStride apart: room for
// that many batches), so no packing has to clear what the last one left. Only its awake rows are
// read or written.
struct PackInput {
  std::span<const float> radius;
  const std::vector<std::uint8_t>& in_pile;
  const Pit& pit;
  std::uint32_t pad_rows;
  std::vector<std::uint32_t>& last_batch;
  std::uint32_t stamp = 0;
  std::uint32_t awake_rows = pad_rows;  // by default none sleeps
};
inline constexpr std::uint32_t kStampStride = 1u << 27;

// Lists that share no sphere (slabs of one parity), packed into one stream of batches: their
// contacts are taken in turn, one from each list, so each batch draws on all of them. Every list
// keeps its own order exactly; lists that share no sphere do not depend on each other's.
using ContactLists = std::span<std::vector<Contact>* const>;

// Packs sphere pairs (their impulses, materials and flags) into batches.
void pack_pairs(ContactLists lists, const PackInput& in, BatchList& out);
// Packs the pit-plane contacts among statics (not the joint colliders) into batches.
void pack_planes(ContactLists lists, const PackInput& in, BatchList& out);

// How many batches ahead for_each_contact asks the cache for the columns it reads. Each batch's
// six columns lie 1 KB apart, more streams than the hardware prefetcher follows: without this,
// reading the impulses from the batches was slower than copying them into the contact lists
// and reading those.
inline constexpr std::size_t kPrefetchReadBatches = 4;

// Calls f(a, b, normal_impulse, friction_impulse) for the lanes lanes_of(batch) names in each
// batch, in batch order: what the passes left in the batches.
template <class LanesOf, class F>
void for_each_lane_of(const BatchList& list, LanesOf&& lanes_of, F&& f) {
  for (std::size_t k = 0; k < list.size(); ++k) {
    if (k + kPrefetchReadBatches < list.size()) {
      const ContactBatch& ahead = list[k + kPrefetchReadBatches];
      for (const void* column : {ahead.a, ahead.b}) __builtin_prefetch(column);
      for (const void* column : {ahead.normal_impulse, ahead.fx, ahead.fy, ahead.fz}) __builtin_prefetch(column);
    }
    const ContactBatch& batch = list[k];
    for (std::uint32_t lanes = lanes_of(batch); lanes != 0; lanes &= lanes - 1) {
      const int lane = std::countr_zero(lanes);
      f(batch.a[lane], batch.b[lane], batch.normal_impulse[lane], Vec3(batch.fx[lane], batch.fy[lane], batch.fz[lane]));
    }
  }
}

// Every contact of the batches.
template <class F>
void for_each_contact(const BatchList& list, F&& f) {
  for_each_lane_of(list, [](const ContactBatch& batch) { return batch.used; }, f);
}

// The contacts that end with a normal impulse (> 0, so not NaN), picked from a batch's lanes
// all at once: a test per contact, taken or not as the pile has it, was a mispredicted branch
// for about one contact in three, and writing the warm-start cache cost a third more.
template <class F>
void for_each_loaded_contact(const BatchList& list, F&& f) {
  for_each_lane_of(list, [](const ContactBatch& batch) {
    std::uint32_t loaded = 0;
    for (int lane = 0; lane < kBatchLanes; ++lane)
      loaded |= static_cast<std::uint32_t>(batch.normal_impulse[lane] > 0.0f) << lane;
    return loaded & batch.used;
  }, f);
}

}  // namespace ballpit
