// Where a run's memory goes, table by table: what each of the world's tables and each system's
// scratch holds between steps (capacity, not size: a list keeps its capacity from the step that
// needed the most). `ballpit run` reports it as bytes a sphere beside the peak RSS
// (app/headless_run.cpp), so the cost of a ball in memory is measured, not guessed (issue 42).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ballpit {

class Scheduler;
class World;

// Bytes a vector (or a Column) holds on the heap.
template <class V>
std::size_t held_bytes(const V& v) {
  return v.capacity() * sizeof(typename V::value_type);
}

struct MemoryItem {
  std::string table;  // a world table ("spheres", "contact lists", ...) or "<system>: <part>"
  std::size_t bytes = 0;
};

// The world's tables, then each scheduled system's scratch, part by part (System::held).
std::vector<MemoryItem> memory_by_table(const World& world, const Scheduler& scheduler);

}  // namespace ballpit
