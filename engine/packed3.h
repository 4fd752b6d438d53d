// A 3-vector held in one SSE register (x, y, z, 0), for the solver's inner loop, where Eigen's
// unaligned Vec3 spends most of its instructions moving components in and out of registers.
//
// Every operation rounds exactly as the Eigen expression it stands for: element-wise + - * /,
// a dot product as x + (y + z) (Eigen's unrolled sum of three), a cross product as Eigen
// writes it. A loop rewritten from Vec3 to Packed3 therefore changes no bit of the state, and
// the state hash proves it. No FMA: a fused multiply-add rounds once where Eigen rounds twice.
//
// Loads and stores move 12 bytes, never 16, so a column of Vec3 needs no padding. Without SSE
// the same operations run on three floats (also with BALLPIT_PACKED3_SCALAR defined).
#pragma once

#include <cmath>

#include "engine/math.h"

#if defined(__SSE2__) && !defined(BALLPIT_PACKED3_SCALAR)
#include <immintrin.h>
#define BALLPIT_PACKED3_SSE 1
#endif

namespace ballpit {

#if BALLPIT_PACKED3_SSE

struct Packed3 {
  __m128 v;  // lanes x, y, z and a fourth that loads as 0 and is never read back

  static Packed3 load(const Vec3& p) {
    const float* f = p.data();
    // __m64 may alias anything (GCC declares it so); a double* would break strict aliasing.
    const __m128 xy = _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(f));
    return {_mm_movelh_ps(xy, _mm_load_ss(f + 2))};
  }
  static Packed3 zero() { return {_mm_setzero_ps()}; }
  static Packed3 of(float x, float y, float z) { return {_mm_setr_ps(x, y, z, 0.0f)}; }

  void store(Vec3& p) const {
    float* f = p.data();
    _mm_storel_pi(reinterpret_cast<__m64*>(f), v);
    _mm_store_ss(f + 2, _mm_movehl_ps(v, v));
  }
  Vec3 vec3() const {
    Vec3 p;
    store(p);
    return p;
  }

  friend Packed3 operator+(Packed3 a, Packed3 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend Packed3 operator-(Packed3 a, Packed3 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend Packed3 operator*(float s, Packed3 a) { return {_mm_mul_ps(_mm_set1_ps(s), a.v)}; }
  friend Packed3 operator*(Packed3 a, float s) { return {_mm_mul_ps(a.v, _mm_set1_ps(s))}; }
  friend Packed3 operator/(Packed3 a, float s) { return {_mm_div_ps(a.v, _mm_set1_ps(s))}; }
  Packed3& operator+=(Packed3 b) { return *this = *this + b; }
  Packed3& operator-=(Packed3 b) { return *this = *this - b; }
  Packed3& operator*=(float s) { return *this = *this * s; }

  // x0 + (x1 + x2) over the lane products, as Eigen sums three.
  friend float dot(Packed3 a, Packed3 b) {
    const __m128 p = _mm_mul_ps(a.v, b.v);
    const __m128 y = _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1));
    const __m128 z = _mm_movehl_ps(p, p);
    return _mm_cvtss_f32(_mm_add_ss(p, _mm_add_ss(y, z)));
  }
  // (a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0), Eigen's Vector3 cross.
  friend Packed3 cross(Packed3 a, Packed3 b) {
    const __m128 a_yzx = _mm_shuffle_ps(a.v, a.v, _MM_SHUFFLE(3, 0, 2, 1));
    const __m128 b_zxy = _mm_shuffle_ps(b.v, b.v, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 a_zxy = _mm_shuffle_ps(a.v, a.v, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 b_yzx = _mm_shuffle_ps(b.v, b.v, _MM_SHUFFLE(3, 0, 2, 1));
    return {_mm_sub_ps(_mm_mul_ps(a_yzx, b_zxy), _mm_mul_ps(a_zxy, b_yzx))};
  }
  // Every component == 0 (so -0 too, and NaN not), as Eigen's isZero(0).
  bool is_zero() const { return (_mm_movemask_ps(_mm_cmpeq_ps(v, _mm_setzero_ps())) & 7) == 7; }
};

#else

struct Packed3 {
  float x, y, z;

  static Packed3 load(const Vec3& p) { return {p.x(), p.y(), p.z()}; }
  static Packed3 zero() { return {0.0f, 0.0f, 0.0f}; }
  static Packed3 of(float x, float y, float z) { return {x, y, z}; }
  void store(Vec3& p) const { p = Vec3(x, y, z); }
  Vec3 vec3() const { return {x, y, z}; }

  friend Packed3 operator+(Packed3 a, Packed3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Packed3 operator-(Packed3 a, Packed3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Packed3 operator*(float s, Packed3 a) { return {s * a.x, s * a.y, s * a.z}; }
  friend Packed3 operator*(Packed3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Packed3 operator/(Packed3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
  Packed3& operator+=(Packed3 b) { return *this = *this + b; }
  Packed3& operator-=(Packed3 b) { return *this = *this - b; }
  Packed3& operator*=(float s) { return *this = *this * s; }

  friend float dot(Packed3 a, Packed3 b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
  friend Packed3 cross(Packed3 a, Packed3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  bool is_zero() const { return x == 0.0f && y == 0.0f && z == 0.0f; }
};

#endif

inline float squared_norm(Packed3 a) { return dot(a, a); }
inline float norm(Packed3 a) { return std::sqrt(squared_norm(a)); }

}  // namespace ballpit
