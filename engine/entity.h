// Entity handles: an index into the registry plus a generation. Destroying an entity bumps the
// generation of its slot, so an old handle to a reused slot is detected as stale instead of
// silently naming the newcomer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ballpit {

struct Entity {
  std::uint32_t index = kInvalidIndex;
  std::uint32_t generation = 0;

  static constexpr std::uint32_t kInvalidIndex = 0xffffffffu;
  bool valid() const { return index != kInvalidIndex; }
  friend bool operator==(Entity, Entity) = default;
};

std::string to_string(Entity e);

class EntityRegistry {
 public:
  Entity create();
  // Throws ballpit::Error if the handle is stale or was never created.
  void destroy(Entity e);
  bool alive(Entity e) const;
  std::uint32_t capacity() const { return static_cast<std::uint32_t>(generations_.size()); }
  std::uint32_t live_count() const { return live_; }
  std::uint32_t generation_of(std::uint32_t index) const { return generations_[index]; }
  void reserve(std::size_t n) { generations_.reserve(n); }

  // Exact internal state, for snapshots (engine/snapshot.h): the free list's order decides
  // which slot create() hands out next, so a resumed run must get it back as it was.
  const std::vector<std::uint32_t>& free_list() const { return free_; }
  std::size_t held_bytes() const {
    return (generations_.capacity() + free_.capacity()) * sizeof(std::uint32_t) + alive_.capacity() / 8;
  }
  // Replaces the registry: every slot not in free_list is alive. Throws ballpit::Error if an
  // index in free_list is out of range or repeated.
  void restore(std::vector<std::uint32_t> generations, std::vector<std::uint32_t> free_list);

 private:
  std::vector<std::uint32_t> generations_;  // current generation of each slot
  std::vector<std::uint32_t> free_;         // destroyed slots, reused LIFO
  std::vector<bool> alive_;
  std::uint32_t live_ = 0;
};

}  // namespace ballpit
