#include "engine/entity.h"

#include "engine/error.h"

namespace ballpit {

std::string to_string(Entity e) {
  return "entity " + std::to_string(e.index) + " (generation " + std::to_string(e.generation) + ")";
}

Entity EntityRegistry::create() {
  ++live_;
  if (!free_.empty()) {
    std::uint32_t index = free_.back();
    free_.pop_back();
    alive_[index] = true;
    return {index, generations_[index]};
  }
  generations_.push_back(0);
  alive_.push_back(true);
  return {static_cast<std::uint32_t>(generations_.size() - 1), 0};
}

bool EntityRegistry::alive(Entity e) const {
  return e.index < generations_.size() && alive_[e.index] && generations_[e.index] == e.generation;
}

void EntityRegistry::destroy(Entity e) {
  if (!alive(e)) throw Error("destroy: " + to_string(e) + " is stale or was never created");
  alive_[e.index] = false;
  ++generations_[e.index];
  free_.push_back(e.index);
  --live_;
}

}  // namespace ballpit
