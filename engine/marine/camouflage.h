// Digital woodland camouflage in the manner of the US Marine Corps' MARPAT: blobs of four
// colours (light khaki, green, brown, near-black) drawn on a coarse 3D grid of "pixels", so the
// blobs have the stepped edges that make the pattern read as digital.
// Decision: the pattern is a pure function of the bind-space position (value noise with fixed
// seeds, no state), so a vertex's colour is the same bits every build and on every machine.
#pragma once

#include <array>
#include <cstdint>

#include "engine/math.h"

namespace ballpit::marine {

using Srgb8 = std::array<std::uint8_t, 4>;  // sRGB red, green, blue, alpha

// The pattern's four colours, sRGB, eyeballed from photographs of MARPAT woodland cloth (the
// published Pantone numbers are not public; these are the usual hobbyist approximations).
inline constexpr Srgb8 kCamoKhaki = {0xa5, 0x9a, 0x6c, 0xff};
inline constexpr Srgb8 kCamoGreen = {0x4c, 0x5a, 0x34, 0xff};
inline constexpr Srgb8 kCamoBrown = {0x5b, 0x4a, 0x36, 0xff};
inline constexpr Srgb8 kCamoBlack = {0x2b, 0x2a, 0x24, 0xff};

// Side of one camouflage pixel (unit: m); real MARPAT squares are about 4 mm, scaled up here so
// the pattern still reads on a mesh with vertices about 1.5 cm apart.
inline constexpr float kCamoPixel = 0.018f;

// The camouflage colour at bind-space position `p` (unit: m). `seed` picks another, unrelated
// sheet of the same pattern (the helmet cover is cut from a different bolt than the blouse).
Srgb8 marpat_woodland(const Vec3& p, std::uint32_t seed = 0);

// Whether `c` is one of the four pattern colours.
bool is_camo_color(const Srgb8& c);

}  // namespace ballpit::marine
