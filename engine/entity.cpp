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

void EntityRegistry::restore(std::vector<std::uint32_t> generations, std::vector<std::uint32_t> free_list) {
  std::vector<bool> alive(generations.size(), true);
  for (std::uint32_t index : free_list) {
    if (index >= generations.size() || !alive[index])
      throw Error("entity free list: index " + std::to_string(index) + " is out of range or repeated");
    alive[index] = false;
  }
  live_ = static_cast<std::uint32_t>(generations.size() - free_list.size());
  generations_ = std::move(generations);
  free_ = std::move(free_list);
  alive_ = std::move(alive);
}

}  // namespace ballpit
