// The marine's skinned body: one smooth closed mesh in his bind pose, dressed (helmet, digital
// woodland camouflage uniform, tan boots, plate carrier, skin-toned face and hands) with vertex
// colours, and weighted to up to four joints, blended across each joint.
// Built from a signed distance field of primitives along his bones (marine_body.cpp says how);
// some 20k triangles, 1.80 m from boot sole (y = 0) to helmet top, deterministic bits.
#pragma once

#include "engine/marine/camouflage.h"
#include "engine/skeleton.h"
#include "engine/skinned_mesh.h"

namespace ballpit::marine {

// His colours besides the camouflage (sRGB): a mid skin tone; coyote/tan rough-out boots as
// issued (~#b59a6e); coyote brown (the "498" of plate carriers and packs).
inline constexpr Srgb8 kSkinTone = {0xc4, 0x8c, 0x6c, 0xff};
inline constexpr Srgb8 kBootTan = {0xb5, 0x9a, 0x6e, 0xff};
inline constexpr Srgb8 kGearCoyote = {0x81, 0x66, 0x45, 0xff};

// The body for make_skeleton()'s joints (mesh bone k is joint k), vertex colours in `colors`.
SkinnedMesh make_body(const Skeleton& skeleton);

}  // namespace ballpit::marine
