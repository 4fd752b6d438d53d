// Animation runtime data: a local pose (each joint's transform relative to its parent, as
// structure-of-arrays like ozz-animation's) and the key cursors that make clip sampling
// amortised O(1): sampling at a time near the last one starts from the last key found.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/math.h"

namespace ballpit {

struct LocalPose {
  std::vector<Vec3> translation;  // (unit: model units)
  std::vector<Quat> rotation;     // unit quaternions
  std::vector<Vec3> scale;

  void resize(std::size_t joints) {
    translation.resize(joints);
    rotation.resize(joints);
    scale.resize(joints);
  }
  std::size_t size() const { return translation.size(); }
};

// Per joint and channel, the index k of the key interval [times[k], times[k + 1]) the last
// sample fell in. One cursor belongs to one clip: sampling another clip through it is allowed
// (it is revalidated) but loses the speed-up.
struct ClipCursor {
  std::vector<std::uint32_t> translation;
  std::vector<std::uint32_t> rotation;
  std::vector<std::uint32_t> scale;

  void reset(std::size_t joints) {
    translation.assign(joints, 0);
    rotation.assign(joints, 0);
    scale.assign(joints, 0);
  }
};

}  // namespace ballpit
