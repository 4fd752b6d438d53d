// Keeps each sphere's position from before the latest physics step, indexed by entity, so the
// renderer can interpolate between the last two steps. It reads SpherePosition and SphereRows
// and writes only its own buffer; added first, it runs before anything that moves or reorders
// spheres.
// Decision: the copy is indexed by entity, not by row, because the grid reorders rows every
// step; the GPU looks a sphere's previous position up through its entity index, so the CPU's
// per-frame work stays a plain copy of columns.
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "engine/math.h"
#include "engine/system.h"

namespace ballpit {

class PreviousPositions final : public System {
 public:
  std::string_view name() const override { return "previous positions"; }
  Access access() const override;
  void run(World& world) override;
  bool data_parallel() const override { return true; }

  // Position before the latest step, by entity index. Entries for entities created since that
  // step are stale; valid() says whether the whole snapshot matches the world.
  std::span<const Vec3> by_entity() const { return by_entity_; }
  bool valid() const { return valid_; }
  // Spawning or removing spheres makes entity indices the snapshot does not cover.
  void invalidate() { valid_ = false; }

 private:
  std::vector<Vec3> by_entity_;
  bool valid_ = false;
};

}  // namespace ballpit
