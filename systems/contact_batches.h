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

#include <cstdint>
#include <span>
#include <vector>

#include "engine/aligned_vector.h"
#include "engine/contact_set.h"
#include "engine/settings.h"
#include "systems/contact_batch.h"

namespace ballpit {

struct BatchList {
  Column<ContactBatch> batches;
  std::vector<std::uint32_t> source;  // per lane of each batch: source_of(list, index), or kNoSource
};

inline constexpr std::uint32_t kNoSource = 0xffffffffu;
// A lane's contact as (list, index in it): up to 32 lists of up to 2^27 contacts.
inline constexpr int kSourceIndexBits = 27;
inline std::uint32_t source_of(std::size_t list, std::uint32_t index) {
  return static_cast<std::uint32_t>(list) << kSourceIndexBits | index;
}

// What packing needs besides the contacts: `radius` per row (m); `in_pile` marks the rows resting
// on another sphere (ContactSet::piled); `pad_rows` is the first padding body. `last_batch` is
// scratch with one entry per row, zeroed once per step and shared by every packing in it, each
// with a `stamp` above every value the packings before it wrote (kStampStride apart: room for
// that many batches), so no packing has to clear what the last one left.
struct PackInput {
  std::span<const float> radius;
  const std::vector<std::uint8_t>& in_pile;
  const Pit& pit;
  std::uint32_t pad_rows;
  std::vector<std::uint32_t>& last_batch;
  std::uint32_t stamp = 0;
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

// Copies each lane's impulses back into the contact it came from.
void unpack_impulses(const BatchList& batches, ContactLists lists);

}  // namespace ballpit
