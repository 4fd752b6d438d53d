// sRGB encoding of 8-bit colour channels (IEC 61966-2-1): what vertex colours and textures
// store, and the linear values glTF's COLOR_0 and material factors hold.
// Decision: the byte -> linear -> byte round trip is exact for all 256 values (the closest
// linear values of two bytes are 3e-4 apart, far above float rounding), so a model exported
// to glTF and imported again keeps its colour bytes.
#pragma once

#include <cmath>
#include <cstdint>

namespace ballpit {

inline float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

inline float linear_to_srgb(float c) {
  return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// A channel in [0, 1] as its nearest byte; out-of-range (and NaN) values clamp.
inline std::uint8_t unit_to_byte(float c) {
  if (!(c > 0.0f)) return 0;
  if (c >= 1.0f) return 255;
  return static_cast<std::uint8_t>(std::lround(c * 255.0f));
}

inline float byte_to_unit(std::uint8_t b) { return static_cast<float>(b) / 255.0f; }

}  // namespace ballpit
