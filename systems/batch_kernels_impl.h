// The batch passes for one instruction set: load a batch's contacts and their bodies into lanes,
// kLanes at a time, run systems/contact_kernel.h, store them back. Included once by each
// systems/batch_kernels_<set>.cpp, which defines BALLPIT_LANES_TARGET and is compiled for that set.
#pragma once

#include <array>
#include <cstddef>

#include "systems/batch_kernels.h"
#include "systems/contact_kernel.h"

namespace ballpit::BALLPIT_LANES_TARGET {

using LaneState = ContactState<Lanes, LaneMask>;
using LaneKernel = ContactKernel<Lanes, LaneMask>;

static_assert(kBatchLanes % kLanes == 0, "a batch runs in whole registers");

// How many batches ahead of the one being solved its columns are fetched into the cache.
inline constexpr std::ptrdiff_t kPrefetchAhead = 2;

// Lanes [first, first + kLanes) of a batch: where each field of theirs starts.
struct LaneSlice {
  ContactBatch& batch;
  int first;

  std::uint32_t* a() const { return batch.a + first; }
  std::uint32_t* b() const { return batch.b + first; }
  Lanes get(const float* column) const { return load(column + first); }
  void set(float* column, Lanes v) const { store(column + first, v); }
  V3<Lanes> get3(const float* x, const float* y, const float* z) const { return {get(x), get(y), get(z)}; }
  void set3(float* x, float* y, float* z, const V3<Lanes>& v) const {
    set(x, v.x);
    set(y, v.y);
    set(z, v.z);
  }
  std::uint32_t bits(std::uint32_t lane_bits) const { return lane_bits >> first & ((1u << kLanes) - 1u); }
};

inline V3<Lanes> xyz(const LaneQuads& q) { return {q.x, q.y, q.z}; }

// Where each quad of a body record lies in it.
inline constexpr std::size_t kVelocity = offsetof(SolverBody, velocity), kSpin = offsetof(SolverBody, spin),
                             kPosition = offsetof(SolverBody, position), kPseudo = offsetof(SolverBody, pseudo);
// Velocity and spin lie side by side, 32-byte aligned: they move together (gather_quad_pair).
static_assert(kSpin == kVelocity + sizeof(Quad) && kVelocity % 32 == 0);

// The records of the lanes' spheres. Taken once per slice: read through the batch's row columns
// at every quad, the compiler had to assume a store to a body may have changed a row.
inline LaneRecords records(SolverBodies& bodies, const std::uint32_t* row) {
  LaneRecords r;
  for (int k = 0; k < kLanes; ++k) r[k] = &bodies.body[row[k]];
  return r;
}

// Rare lanes, one at a time: an impact's position shift (Relax), applied after the move that
// the shift corrects, split by the spheres' mobilities (a plane does not move).
template <BatchKind kind>
inline void shift_apart(const LaneSlice& s, std::uint32_t lanes, SolverBodies& bodies, const LaneState& c) {
  for (; lanes; lanes &= lanes - 1) {
    const int k = __builtin_ctz(lanes);
    const float ma = c.ma[k], mb = c.mb[k], total = ma + mb, shift = c.impact_shift[k];
    Quad& xa = bodies.body[s.a()[k]].position;
    const float sa = kind == BatchKind::Pairs ? shift * ma / total : shift;
    xa = {xa.x + c.n.x[k] * sa, xa.y + c.n.y[k] * sa, xa.z + c.n.z[k] * sa, xa.w};
    if constexpr (kind == BatchKind::Pairs) {
      Quad& xb = bodies.body[s.b()[k]].position;
      const float sb = shift * mb / total;
      xb = {xb.x - c.n.x[k] * sb, xb.y - c.n.y[k] * sb, xb.z - c.n.z[k] * sb, xb.w};
    }
    s.batch.impact_shift[s.first + k] = 0.0f;
  }
}

// A sleeper is immobile this step, so exactly one side of its pair has zero mobility; a blow
// that would change the mover's speed by more than args.wake_speed (kStruckWakeFactor times the
// settings' wake speed, systems/sleep_regions.h) wakes it (the sleep system acts on the
// request after the step).
inline void request_wakes(const LaneSlice& s, const LaneState& c, const BatchPassArgs& args) {
  const LaneMask one_asleep = (c.ma == 0.0f) != (c.mb == 0.0f);
  const LaneMask hard = c.applied * (c.ma + c.mb) > args.wake_speed;
  for (std::uint32_t lanes = bits_of_mask(one_asleep & hard) & s.bits(s.batch.used); lanes; lanes &= lanes - 1) {
    const int k = __builtin_ctz(lanes);
    args.wake_requests[c.ma[k] == 0.0f ? s.a()[k] : s.b()[k]] = 1;
  }
}

template <Pass pass, bool spin, BatchKind kind>
void run_slice(const LaneSlice& s, SolverBodies& bodies, const BatchPassArgs& args, BatchPassResult& result) {
  constexpr bool pairs = kind == BatchKind::Pairs;
  // Solve keeps its pushed flags in the spin quads, so it moves them even where nothing spins.
  constexpr bool spin_quads = spin || pass == Pass::Solve;
  ContactBatch& batch = s.batch;
  LaneState c;
  const LaneRecords ra = records(bodies, s.a());
  const LaneRecords rb = pairs ? records(bodies, s.b()) : LaneRecords{};
  LaneQuads va, vb{}, sa{}, sb{}, pa{}, pb{};
  if constexpr (spin_quads) {
    gather_quad_pair(ra, kVelocity, va, sa);
    if constexpr (pairs) gather_quad_pair(rb, kVelocity, vb, sb);
  } else {
    va = gather_quads(ra, kVelocity);
    if constexpr (pairs) vb = gather_quads(rb, kVelocity);
  }
  Lanes approach_accel{};
  if constexpr (pairs) {
    if (pass == Pass::Relax || !args.frames_current) {
      const LaneQuads xa = gather_quads(ra, kPosition);
      const LaneQuads xb = gather_quads(rb, kPosition);
      pair_frame(xyz(xa), xyz(xb), xa.w, xb.w, c.n, c.gap);
      s.set3(batch.nx, batch.ny, batch.nz, c.n);
      s.set(batch.gap, c.gap);
    } else {
      c.n = s.get3(batch.nx, batch.ny, batch.nz);
      c.gap = s.get(batch.gap);
    }
  } else {
    // A plane's normal is fixed; its gap is one dot product, cheaper to compute than to keep.
    const LaneQuads xa = gather_quads(ra, kPosition);
    c.n = s.get3(batch.nx, batch.ny, batch.nz);
    c.gap = -dot(c.n, xyz(xa)) - s.get(batch.plane_offset) - xa.w;
    const V3<Lanes> g{broadcast<Lanes>(args.gravity[0]), broadcast<Lanes>(args.gravity[1]),
                      broadcast<Lanes>(args.gravity[2])};
    approach_accel = -dot(g, c.n);
  }
  if constexpr (pass == Pass::Solve) {
    pa = gather_quads(ra, kPseudo);
    if constexpr (pairs) pb = gather_quads(rb, kPseudo);
  }
  c.reach = s.get(batch.reach);
  c.va = xyz(va);
  c.ma = va.w;
  c.vb = xyz(vb);
  c.mb = vb.w;
  c.sa = xyz(sa);
  c.sb = xyz(sb);
  c.pa = xyz(pa);
  c.pb = xyz(pb);
  c.pushed_a = sa.w;
  c.pushed_b = sb.w;
  c.normal_impulse = s.get(batch.normal_impulse);
  c.friction_impulse = s.get3(batch.fx, batch.fy, batch.fz);
  c.friction = s.get(batch.friction);
  c.restitution = s.get(batch.restitution);
  c.impact_shift = s.get(batch.impact_shift);
  c.loaded_last_step = mask_of_bits(s.bits(batch.loaded_last_step));
  c.free_pair = mask_of_bits(s.bits(batch.free_pair));

  if constexpr (pass == Pass::WarmStart) LaneKernel::warm_start<spin, spin && pairs>(c);
  else LaneKernel::solve<pass, spin, !pairs>(c, approach_accel, args.params);

  s.set(batch.normal_impulse, c.normal_impulse);
  s.set3(batch.fx, batch.fy, batch.fz, c.friction_impulse);
  if constexpr (pass != Pass::WarmStart) s.set(batch.impact_shift, c.impact_shift);
  // Only the used lanes write: the padding bodies are shared by every batch, and threads that
  // wrote them (the same values) took each other's cache lines, which made 2 threads slower
  // than 1 at 10k spheres.
  const std::uint32_t used = s.bits(batch.used);
  if constexpr (spin_quads) {
    scatter_quad_pair(ra, kVelocity, used, {c.va.x, c.va.y, c.va.z, c.ma}, {c.sa.x, c.sa.y, c.sa.z, c.pushed_a});
    if constexpr (pairs)
      scatter_quad_pair(rb, kVelocity, used, {c.vb.x, c.vb.y, c.vb.z, c.mb}, {c.sb.x, c.sb.y, c.sb.z, c.pushed_b});
  } else {
    scatter_quads(ra, kVelocity, used, {c.va.x, c.va.y, c.va.z, c.ma});
    if constexpr (pairs) scatter_quads(rb, kVelocity, used, {c.vb.x, c.vb.y, c.vb.z, c.mb});
  }
  if constexpr (pass == Pass::Solve) {
    scatter_quads(ra, kPseudo, used, {c.pa.x, c.pa.y, c.pa.z, pa.w});
    if constexpr (pairs) {
      scatter_quads(rb, kPseudo, used, {c.pb.x, c.pb.y, c.pb.z, pb.w});
      if (args.wake_requests) request_wakes(s, c, args);
    }
  }
  if constexpr (pass == Pass::Relax) {
    const std::uint32_t shifts = bits_of_mask(c.impact_shift != 0.0f) & s.bits(batch.used);
    if (shifts) {
      shift_apart<kind>(s, shifts, bodies, c);
      result.shifted = true;
    }
  }
}

template <Pass pass, bool spin, BatchKind kind>
void run_batches(ContactBatch* begin, ContactBatch* end, SolverBodies& bodies, const BatchPassArgs& args,
                 BatchPassResult& result) {
  for (ContactBatch* batch = begin; batch != end; ++batch) {
    // The batches stream through memory in order, but the hardware's prefetch fell behind: a
    // load of the batch's columns was the slowest instruction of the pass.
    if (end - batch > kPrefetchAhead)
      for (std::size_t line = 0; line < sizeof(ContactBatch); line += 64)
        __builtin_prefetch(reinterpret_cast<const char*>(batch + kPrefetchAhead) + line);
    // And the next batch's bodies, whose rows that batch's columns (fetched a batch ago) now
    // name: each lane's gather waited on its body's line, 32 of them a batch, from wherever the
    // last pass had left them (the 100k pour, 2 threads: solver 30.5 -> 27.9 ms a step).
    if (end - batch > 1) {
      const ContactBatch& next = batch[1];
      for (int k = 0; k < kBatchLanes; ++k) {
        __builtin_prefetch(&bodies.body[next.a[k]], 1);
        if constexpr (kind == BatchKind::Pairs) __builtin_prefetch(&bodies.body[next.b[k]], 1);
      }
    }
    for (int first = 0; first < kBatchLanes; first += kLanes) {
      const LaneSlice slice{*batch, first};
      if (slice.bits(batch->used)) run_slice<pass, spin, kind>(slice, bodies, args, result);  // padding changes nothing
    }
  }
}

template <BatchKind kind>
constexpr auto passes_of_kind() {
  using P = BatchPass;
  return std::array<std::array<P, 2>, 3>{{{run_batches<Pass::WarmStart, false, kind>, run_batches<Pass::WarmStart, true, kind>},
                                           {run_batches<Pass::Solve, false, kind>, run_batches<Pass::Solve, true, kind>},
                                           {run_batches<Pass::Relax, false, kind>, run_batches<Pass::Relax, true, kind>}}};
}

inline BatchKernels make_batch_kernels(std::string_view name) {
  BatchKernels k{name, {}};
  const auto pairs = passes_of_kind<BatchKind::Pairs>();
  const auto planes = passes_of_kind<BatchKind::Planes>();
  for (int p = 0; p < 3; ++p)
    for (int spin = 0; spin < 2; ++spin) {
      k.pass[0][p][spin] = pairs[p][spin];
      k.pass[1][p][spin] = planes[p][spin];
    }
  return k;
}

}  // namespace ballpit::BALLPIT_LANES_TARGET
