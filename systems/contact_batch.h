// A batch of sixteen contacts that share no sphere, stored a column per field: the unit of work
// of the solver's lane kernels (systems/batch_kernels.h), which move each field in and out of
// their lanes with one load and one store. A batch holds sphere pairs, or spheres against pit
// planes; systems/contact_batches.h makes both.
#pragma once

#include <cstdint>

namespace ballpit {

inline constexpr int kBatchLanes = 16;

struct alignas(64) ContactBatch {
  // Left uninitialised: packing writes every lane, the empty ones as padding (1 KB a batch that
  // zeroing first cost a sixth of the packing).
  ContactBatch() {}

  std::uint32_t a[kBatchLanes];  // sphere row that generated the contact
  std::uint32_t b[kBatchLanes];  // partner row (in the slab or the next), or the tagged plane
  // The frame as the last pass that computed it left it: unit normal from a into the partner,
  // and for a pair the gap (m). A plane's normal never changes, and its gap, -n . x - offset - r,
  // is cheaper to compute than to keep: a plane batch keeps the plane's offset (m) in its place,
  // so no batch carries a column it does not use.
  float nx[kBatchLanes], ny[kBatchLanes], nz[kBatchLanes];
  union {
    float gap[kBatchLanes];           // pair batches
    float plane_offset[kBatchLanes];  // plane batches
  };
  float normal_impulse[kBatchLanes];                        // (unit: N s)
  float fx[kBatchLanes], fy[kBatchLanes], fz[kBatchLanes];  // friction impulse (unit: N s)
  float friction[kBatchLanes];                              // combined Coulomb coefficient
  float restitution[kBatchLanes];                           // combined restitution
  float reach[kBatchLanes];  // -kWarmStartReach x the smaller radius: deeper overlaps are not warm-started (m)
  float impact_shift[kBatchLanes];  // (1+e) x gap of an impact this substep, undone after the move (m)
  std::uint32_t loaded_last_step;   // lane bits: carried load at the end of the last step
  std::uint32_t free_pair;          // lane bits: no sphere of it rests in a pile (else no impact shift, nor a plane's impact)
  std::uint32_t used;               // lane bits: lanes that hold a contact
};

}  // namespace ballpit
