#include "engine/marine/camouflage.h"

#include <cmath>

namespace ballpit::marine {

namespace {

// A 32-bit integer hash (Chris Wellons' "lowbias32"), good enough for value noise.
std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// Uniform value in [0, 1) at an integer lattice point.
float lattice(int x, int y, int z, std::uint32_t seed) {
  std::uint32_t h = hash32(static_cast<std::uint32_t>(x) * 0x8da6b343U ^ hash32(seed));
  h = hash32(h ^ static_cast<std::uint32_t>(y) * 0xd8163841U);
  h = hash32(h ^ static_cast<std::uint32_t>(z) * 0xcb1ab31fU);
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

// Trilinear value noise with a smoothstep fade, in [0, 1).
float value_noise(const Vec3& p, std::uint32_t seed) {
  const float fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const int x = static_cast<int>(fx), y = static_cast<int>(fy), z = static_cast<int>(fz);
  const float tx = smooth(p.x() - fx), ty = smooth(p.y() - fy), tz = smooth(p.z() - fz);
  float c[2][2];
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k) {
      const float a = lattice(x, y + j, z + k, seed), b = lattice(x + 1, y + j, z + k, seed);
      c[j][k] = a + (b - a) * tx;
    }
  const float c0 = c[0][0] + (c[1][0] - c[0][0]) * ty;
  const float c1 = c[0][1] + (c[1][1] - c[0][1]) * ty;
  return c0 + (c1 - c0) * tz;
}

// Two octaves: blobs about 12 cm across with ragged edges.
float blobs(const Vec3& p, float scale, std::uint32_t seed) {
  return 0.7f * value_noise(p * scale, seed) + 0.3f * value_noise(p * (2.7f * scale), seed + 101U);
}

}  // namespace

Srgb8 marpat_woodland(const Vec3& p, std::uint32_t seed) {
  // Snap to the centre of the pixel the point lies in: the whole pixel takes one colour.
  const Vec3 cell((std::floor(p.x() / kCamoPixel) + 0.5f) * kCamoPixel,
                  (std::floor(p.y() / kCamoPixel) + 0.5f) * kCamoPixel,
                  (std::floor(p.z() / kCamoPixel) + 0.5f) * kCamoPixel);
  // A little per-pixel jitter on the thresholds frays each blob's outline pixel by pixel.
  const int ix = static_cast<int>(std::floor(p.x() / kCamoPixel));
  const int iy = static_cast<int>(std::floor(p.y() / kCamoPixel));
  const int iz = static_cast<int>(std::floor(p.z() / kCamoPixel));
  const float jitter = 0.08f * (lattice(ix, iy, iz, seed + 7U) - 0.5f);
  // Layers painted in order, as the cloth is printed: khaki ground, green, brown, black on top.
  // The thresholds set the shares; over his uniform and helmet vertices they come to khaki
  // 28 %, green 32 %, brown 24 %, black 16 % (MARPAT woodland is roughly a quarter each, with
  // less black).
  Srgb8 c = kCamoKhaki;
  if (blobs(cell, 9.0f, seed + 1U) + jitter > 0.44f) c = kCamoGreen;
  if (blobs(cell, 11.0f, seed + 2U) + jitter > 0.58f) c = kCamoBrown;
  if (blobs(cell, 14.0f, seed + 3U) + jitter > 0.63f) c = kCamoBlack;
  return c;
}

bool is_camo_color(const Srgb8& c) {
  return c == kCamoKhaki || c == kCamoGreen || c == kCamoBrown || c == kCamoBlack;
}

}  // namespace ballpit::marine
