#include "engine/memory_use.h"

#include "engine/scheduler.h"
#include "engine/world.h"

namespace ballpit {

std::vector<MemoryItem> memory_by_table(const World& world, const Scheduler& scheduler) {
  std::vector<MemoryItem> items;
  const SphereTable::HeldBytes spheres = world.spheres.held();
  items.push_back({"spheres", spheres.columns});
  items.push_back({"spheres: reorder targets", spheres.reorder});

  const ContactSet& c = world.contacts;
  std::size_t lists = held_bytes(c.slabs) + held_bytes(c.piled) + held_bytes(c.wake_requests);
  for (const SlabContacts& s : c.slabs) lists += held_bytes(s.pairs) + held_bytes(s.statics) + held_bytes(s.serial);
  items.push_back({"contact lists", lists});
  items.push_back({"warm-start cache", held_bytes(c.warm_begin) + held_bytes(c.warm) + held_bytes(c.row_slept)});
  items.push_back({"warm-start cache: sleepers'",
                   held_bytes(c.kept.of) + held_bytes(c.kept.partners) + held_bytes(c.kept.entries)});

  const SpatialGrid& g = world.grid;
  items.push_back({"grid", held_bytes(g.cell_start) + held_bytes(g.cell_of_row) + held_bytes(g.new_to_old)});
  items.push_back({"entities", world.entities.held_bytes()});

  for (std::size_t i = 0; i < scheduler.size(); ++i) {
    const System& s = scheduler.system(i);
    for (const MemoryItem& part : s.held()) items.push_back({std::string(s.name()) + ": " + part.table, part.bytes});
  }
  return items;
}

}  // namespace ballpit
