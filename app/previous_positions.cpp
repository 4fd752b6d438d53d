#include "app/previous_positions.h"

#include <cstdint>

#include "engine/world.h"

namespace ballpit {

Access PreviousPositions::access() const {
  return {ColumnSet{ColumnId::SpherePosition, ColumnId::SphereRows}, ColumnSet{}};
}

void PreviousPositions::run(World& world) {
  std::span<const Vec3> position = world.spheres.position();
  std::span<const std::uint32_t> entity = world.spheres.entity_index();
  if (by_entity_.size() < world.entities.capacity()) by_entity_.resize(world.entities.capacity(), Vec3::Zero());
  const std::int64_t n = static_cast<std::int64_t>(position.size());
  Vec3* out = by_entity_.data();
  // Each row writes a different entity slot, so the scatter has no races.
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) out[entity[static_cast<std::size_t>(i)]] = position[static_cast<std::size_t>(i)];
  valid_ = true;
}

}  // namespace ballpit
