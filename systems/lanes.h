// A register of floats computed as one: the lane type of the solver's contact kernels. Each lane
// holds one contact of a batch of sixteen (systems/contact_batch.h); the kernels are written
// once, against this type, and compiled three times (systems/batch_kernels_*.cpp): 16 lanes for
// AVX-512, 8 for AVX2 and 4 for any other CPU (SSE2, NEON), which run a batch in 1, 2 or 4 goes.
// A wider type than the register (16 floats on AVX2) spilled most of the kernel to the stack
// and ran 3x slower. Only IEEE-exact operations appear (+ - * /, sqrt, compares, selects; no
// fused multiply-add, no reciprocal estimates), so every build computes the same bits and the
// choice of kernel, like the number of threads, never changes a result.
//
// Body state is stored as 16-byte quads (systems/solver_bodies.h). A batch reads the quads of
// its bodies and transposes them into four lane vectors (x, y, z, w), and back: that
// transpose, not the arithmetic, is most of what a batch costs, so it is the one part written
// per instruction set.
//
// This header is compiled with different target flags in different files. Everything in it
// lives in a namespace named after the target (BALLPIT_LANES_TARGET), so no inline function
// compiled for AVX-512 can stand in for its plain twin at link time.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

#include "systems/solver_bodies.h"

#if defined(__AVX2__) || defined(__AVX512F__)
// GCC 12's AVX-512 intrinsics (_mm512_unpacklo_ps, _mm512_extractf32x4_ps, the casts) start
// from an undefined register and warn that it is used uninitialised where they are inlined (GCC
// bug 105593, fixed in GCC 13). The warning is located in the header, so silencing it there
// silences nothing in this project's code.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop
#else
#include <immintrin.h>
#endif
#endif

#ifndef BALLPIT_LANES_TARGET
#error "define BALLPIT_LANES_TARGET (the file's instruction set) before including systems/lanes.h"
#endif

namespace ballpit::BALLPIT_LANES_TARGET {

#if defined(__AVX512F__)
inline constexpr int kLanes = 16;
#elif defined(__AVX2__)
inline constexpr int kLanes = 8;
#else
inline constexpr int kLanes = 4;
#endif

using Lanes = float __attribute__((vector_size(4 * kLanes)));
using LaneMask = std::int32_t __attribute__((vector_size(4 * kLanes)));  // all bits set or clear

struct LaneQuads {
  Lanes x, y, z, w;
};

// The body record of each lane, and where in it a quad lies: the addresses of a batch's quads.
using LaneRecords = std::array<SolverBody*, kLanes>;
inline float* quad_at(const LaneRecords& r, int k, std::size_t offset) {
  return reinterpret_cast<float*>(reinterpret_cast<char*>(r[k]) + offset);
}

inline Lanes load(const float* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(float* p, Lanes v) { std::memcpy(p, &v, sizeof v); }

inline Lanes select(LaneMask m, Lanes a, Lanes b) { return m ? a : b; }
// a > b ? a : b lane by lane, the semantics of MAXPS; the one-lane overloads below agree.
inline Lanes max(Lanes a, Lanes b) { return a > b ? a : b; }
inline Lanes min(Lanes a, Lanes b) { return a < b ? a : b; }
inline LaneMask mask_not(LaneMask m) { return ~m; }

// The same operations on one float, for contacts solved one at a time (pit planes, joint
// colliders): the kernels are templates over the lane type.
inline float select(bool m, float a, float b) { return m ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline float min(float a, float b) { return a < b ? a : b; }
inline bool mask_not(bool m) { return !m; }
inline bool any(bool m) { return m; }
inline float sqrt(float v) { return __builtin_sqrtf(v); }

#if defined(__AVX512F__)

inline __m512 raw(Lanes v) { return std::bit_cast<__m512>(v); }
inline Lanes lanes(__m512 v) { return std::bit_cast<Lanes>(v); }
inline Lanes sqrt(Lanes v) { return lanes(_mm512_sqrt_ps(raw(v))); }
// Lane k of the mask is bit k.
inline std::uint32_t bits_of_mask(LaneMask m) {
  const __m512i i = std::bit_cast<__m512i>(m);
  return _mm512_test_epi32_mask(i, i);
}
inline LaneMask mask_of_bits(std::uint32_t bits) {
  return std::bit_cast<LaneMask>(_mm512_maskz_mov_epi32(static_cast<__mmask16>(bits), _mm512_set1_epi32(-1)));
}

// Quads q0..q15 as four registers of four quads each: register k holds quads k, k+4, k+8,
// k+12, one per 128-bit lane, so that the 4x4 transposes inside each 128-bit lane yield the
// components in lane order 0..15.
inline __m512 four_quads(const LaneRecords& rec, std::size_t offset, int k) {
  __m512 r = _mm512_castps128_ps512(_mm_load_ps(quad_at(rec, k, offset)));
  r = _mm512_insertf32x4(r, _mm_load_ps(quad_at(rec, k + 4, offset)), 1);
  r = _mm512_insertf32x4(r, _mm_load_ps(quad_at(rec, k + 8, offset)), 2);
  return _mm512_insertf32x4(r, _mm_load_ps(quad_at(rec, k + 12, offset)), 3);
}

// Registers r[k] holding quads k, k+4, k+8, k+12 (one per 128-bit lane) as four lane vectors:
// a 4x4 transpose inside each 128-bit lane.
inline LaneQuads lanes_of_quads(const __m512 (&r)[4]) {
  const __m512 t0 = _mm512_unpacklo_ps(r[0], r[1]), t1 = _mm512_unpackhi_ps(r[0], r[1]);
  const __m512 t2 = _mm512_unpacklo_ps(r[2], r[3]), t3 = _mm512_unpackhi_ps(r[2], r[3]);
  return {lanes(_mm512_shuffle_ps(t0, t2, 0x44)), lanes(_mm512_shuffle_ps(t0, t2, 0xEE)),
          lanes(_mm512_shuffle_ps(t1, t3, 0x44)), lanes(_mm512_shuffle_ps(t1, t3, 0xEE))};
}

// And back: r[k] gets the quads of lanes k, k+4, k+8, k+12.
inline void quads_of_lanes(const LaneQuads& q, __m512 (&r)[4]) {
  const __m512 t0 = _mm512_unpacklo_ps(raw(q.x), raw(q.y)), t1 = _mm512_unpackhi_ps(raw(q.x), raw(q.y));
  const __m512 t2 = _mm512_unpacklo_ps(raw(q.z), raw(q.w)), t3 = _mm512_unpackhi_ps(raw(q.z), raw(q.w));
  r[0] = _mm512_shuffle_ps(t0, t2, 0x44);
  r[1] = _mm512_shuffle_ps(t0, t2, 0xEE);
  r[2] = _mm512_shuffle_ps(t1, t3, 0x44);
  r[3] = _mm512_shuffle_ps(t1, t3, 0xEE);
}

inline LaneQuads gather_quads(const LaneRecords& rec, std::size_t offset) {
  const __m512 r[4] = {four_quads(rec, offset, 0), four_quads(rec, offset, 1), four_quads(rec, offset, 2),
                       four_quads(rec, offset, 3)};
  return lanes_of_quads(r);
}

// Lane k writes its quad only where bit k of `write_mask` is set.
inline void scatter_quads(const LaneRecords& rec, std::size_t offset, std::uint32_t write_mask, const LaneQuads& q) {
  __m512 r[4];
  quads_of_lanes(q, r);
  for (int k = 0; k < 4; ++k) {
    if (write_mask >> k & 1u) _mm_store_ps(quad_at(rec, k, offset), _mm512_castps512_ps128(r[k]));
    if (write_mask >> (k + 4) & 1u) _mm_store_ps(quad_at(rec, k + 4, offset), _mm512_extractf32x4_ps(r[k], 1));
    if (write_mask >> (k + 8) & 1u) _mm_store_ps(quad_at(rec, k + 8, offset), _mm512_extractf32x4_ps(r[k], 2));
    if (write_mask >> (k + 12) & 1u) _mm_store_ps(quad_at(rec, k + 12, offset), _mm512_extractf32x4_ps(r[k], 3));
  }
}

// Two quads side by side in a record (`offset` 32-byte aligned) move as one 256-bit oct: half
// the loads and stores of two gather_quads or scatter_quads, and fewer shuffles, which all
// compete for one port.
inline __m256 oct_at(const LaneRecords& rec, int k, std::size_t offset) { return _mm256_load_ps(quad_at(rec, k, offset)); }
inline __m512 two_octs(__m256 low, __m256 high) {
  return _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_castps_pd(low)), _mm256_castps_pd(high), 1));
}

inline void gather_quad_pair(const LaneRecords& rec, std::size_t offset, LaneQuads& first, LaneQuads& second) {
  __m512 f[4], s[4];
  for (int k = 0; k < 4; ++k) {
    // 128-bit lanes [first k, second k, first k+4, second k+4], and the same of k+8 and k+12.
    const __m512 ab = two_octs(oct_at(rec, k, offset), oct_at(rec, k + 4, offset));
    const __m512 cd = two_octs(oct_at(rec, k + 8, offset), oct_at(rec, k + 12, offset));
    f[k] = _mm512_shuffle_f32x4(ab, cd, _MM_SHUFFLE(2, 0, 2, 0));  // as four_quads(rec, offset, k)
    s[k] = _mm512_shuffle_f32x4(ab, cd, _MM_SHUFFLE(3, 1, 3, 1));
  }
  first = lanes_of_quads(f);
  second = lanes_of_quads(s);
}

inline void scatter_quad_pair(const LaneRecords& rec, std::size_t offset, std::uint32_t write_mask, const LaneQuads& first,
                              const LaneQuads& second) {
  __m512 f[4], s[4];
  quads_of_lanes(first, f);
  quads_of_lanes(second, s);
  // 128-bit lanes [f0, s0, f1, s1] and [f2, s2, f3, s3]: the octs of lanes k, k+4 and of k+8, k+12.
  const __m512i near = _mm512_setr_epi32(0, 1, 2, 3, 16, 17, 18, 19, 4, 5, 6, 7, 20, 21, 22, 23);
  const __m512i far = _mm512_setr_epi32(8, 9, 10, 11, 24, 25, 26, 27, 12, 13, 14, 15, 28, 29, 30, 31);
  auto low = [](__m512 v) { return _mm512_castps512_ps256(v); };
  auto high = [](__m512 v) { return _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1)); };
  for (int k = 0; k < 4; ++k) {
    const __m512 ab = _mm512_permutex2var_ps(f[k], near, s[k]), cd = _mm512_permutex2var_ps(f[k], far, s[k]);
    if (write_mask >> k & 1u) _mm256_store_ps(quad_at(rec, k, offset), low(ab));
    if (write_mask >> (k + 4) & 1u) _mm256_store_ps(quad_at(rec, k + 4, offset), high(ab));
    if (write_mask >> (k + 8) & 1u) _mm256_store_ps(quad_at(rec, k + 8, offset), low(cd));
    if (write_mask >> (k + 12) & 1u) _mm256_store_ps(quad_at(rec, k + 12, offset), high(cd));
  }
}

#elif defined(__AVX2__)

inline __m256 raw(Lanes v) { return std::bit_cast<__m256>(v); }
inline Lanes lanes(__m256 v) { return std::bit_cast<Lanes>(v); }
inline Lanes sqrt(Lanes v) { return lanes(_mm256_sqrt_ps(raw(v))); }
inline std::uint32_t bits_of_mask(LaneMask m) {
  return static_cast<std::uint32_t>(_mm256_movemask_ps(std::bit_cast<__m256>(m)));
}
inline LaneMask mask_of_bits(std::uint32_t bits) {
  const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  return std::bit_cast<LaneMask>(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), bit), bit));
}

// Quads k and k+4, one per 128-bit lane.
inline __m256 two_quads(const LaneRecords& rec, std::size_t offset, int k) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(quad_at(rec, k, offset))),
                              _mm_load_ps(quad_at(rec, k + 4, offset)), 1);
}

inline LaneQuads gather_quads(const LaneRecords& rec, std::size_t offset) {
  const __m256 r0 = two_quads(rec, offset, 0), r1 = two_quads(rec, offset, 1);
  const __m256 r2 = two_quads(rec, offset, 2), r3 = two_quads(rec, offset, 3);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  return {lanes(_mm256_shuffle_ps(t0, t2, 0x44)), lanes(_mm256_shuffle_ps(t0, t2, 0xEE)),
          lanes(_mm256_shuffle_ps(t1, t3, 0x44)), lanes(_mm256_shuffle_ps(t1, t3, 0xEE))};
}

inline void scatter_quads(const LaneRecords& rec, std::size_t offset, std::uint32_t write_mask, const LaneQuads& q) {
  const __m256 t0 = _mm256_unpacklo_ps(raw(q.x), raw(q.y)), t1 = _mm256_unpackhi_ps(raw(q.x), raw(q.y));
  const __m256 t2 = _mm256_unpacklo_ps(raw(q.z), raw(q.w)), t3 = _mm256_unpackhi_ps(raw(q.z), raw(q.w));
  const __m256 r[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE),
                       _mm256_shuffle_ps(t1, t3, 0x44), _mm256_shuffle_ps(t1, t3, 0xEE)};
  for (int k = 0; k < 4; ++k) {
    if (write_mask >> k & 1u) _mm_store_ps(quad_at(rec, k, offset), _mm256_castps256_ps128(r[k]));
    if (write_mask >> (k + 4) & 1u) _mm_store_ps(quad_at(rec, k + 4, offset), _mm256_extractf128_ps(r[k], 1));
  }
}

#else

inline Lanes sqrt(Lanes v) {
  for (int k = 0; k < kLanes; ++k) v[k] = __builtin_sqrtf(v[k]);
  return v;
}
inline std::uint32_t bits_of_mask(LaneMask m) {
  std::uint32_t bits = 0;
  for (int k = 0; k < kLanes; ++k) bits |= (m[k] != 0 ? 1u : 0u) << k;
  return bits;
}
inline LaneMask mask_of_bits(std::uint32_t bits) {
  LaneMask m;
  for (int k = 0; k < kLanes; ++k) m[k] = (bits >> k & 1u) ? -1 : 0;
  return m;
}

inline LaneQuads gather_quads(const LaneRecords& rec, std::size_t offset) {
  LaneQuads q;
  for (int k = 0; k < kLanes; ++k) {
    const float* b = quad_at(rec, k, offset);
    q.x[k] = b[0];
    q.y[k] = b[1];
    q.z[k] = b[2];
    q.w[k] = b[3];
  }
  return q;
}

inline void scatter_quads(const LaneRecords& rec, std::size_t offset, std::uint32_t write_mask, const LaneQuads& q) {
  for (int k = 0; k < kLanes; ++k) {
    if (!(write_mask >> k & 1u)) continue;
    float* b = quad_at(rec, k, offset);
    b[0] = q.x[k];
    b[1] = q.y[k];
    b[2] = q.z[k];
    b[3] = q.w[k];
  }
}

#endif

#if !defined(__AVX512F__)
// Two quads side by side in a record, as two gathers (only AVX-512 gains by moving them as one).
inline void gather_quad_pair(const LaneRecords& rec, std::size_t offset, LaneQuads& first, LaneQuads& second) {
  first = gather_quads(rec, offset);
  second = gather_quads(rec, offset + sizeof(Quad));
}
inline void scatter_quad_pair(const LaneRecords& rec, std::size_t offset, std::uint32_t write_mask, const LaneQuads& first,
                              const LaneQuads& second) {
  scatter_quads(rec, offset, write_mask, first);
  scatter_quads(rec, offset + sizeof(Quad), write_mask, second);
}
#endif

inline bool any(LaneMask m) { return bits_of_mask(m) != 0; }

}  // namespace ballpit::BALLPIT_LANES_TARGET
