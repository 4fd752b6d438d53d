#include "engine/sphere_table.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <new>
#include <sstream>
#include <type_traits>

#include "engine/error.h"
#include "engine/memory_use.h"

namespace ballpit {

namespace {

std::string vec_text(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

}  // namespace

void SphereTable::add(Entity e, const SphereDesc& d) {
  auto fail = [&](const std::string& what) { throw Error("sphere " + to_string(e) + ": " + what); };
  if (!all_finite(d.position)) fail("position must be finite, got " + vec_text(d.position));
  if (!all_finite(d.velocity)) fail("velocity must be finite, got " + vec_text(d.velocity));
  if (!all_finite(d.angular_velocity)) fail("angular velocity must be finite, got " + vec_text(d.angular_velocity));
  if (!has_angular_ && d.angular_velocity != Vec3::Zero())
    fail("angular velocity " + vec_text(d.angular_velocity) + " rad/s needs the angular columns (set_angular)");
  if (!(d.radius > 0.0f) || !std::isfinite(d.radius))
    fail("radius must be a finite number > 0 m, got " + std::to_string(d.radius));
  if (!(d.mass > 0.0f) || !std::isfinite(d.mass) || !std::isfinite(1.0f / d.mass))
    fail("mass must be a finite number > 0 kg whose inverse is finite, got " + std::to_string(d.mass));
  if (e.index < row_of_.size() && row_of_[e.index] != kNoRow) fail("is already a sphere");

  if (row_of_.size() <= e.index) row_of_.resize(e.index + 1, kNoRow);
  row_of_[e.index] = static_cast<std::uint32_t>(entity_.size());
  position_.push_back(d.position);
  velocity_.push_back(d.velocity);
  if (has_angular_) angular_velocity_.push_back(d.angular_velocity);
  radius_.push_back(d.radius);
  inv_mass_.push_back(1.0f / d.mass);
  material_.push_back(d.material);
  color_.push_back(d.color);
  still_time_.push_back(0.0f);
  still_from_.push_back(d.position);
  asleep_.push_back(0);
  entity_.push_back(e.index);
  generation_.push_back(e.generation);
}

bool SphereTable::contains(Entity e) const {
  if (e.index >= row_of_.size() || row_of_[e.index] == kNoRow) return false;
  return generation_[row_of_[e.index]] == e.generation;
}

std::uint32_t SphereTable::row(Entity e) const {
  if (!contains(e)) throw Error(to_string(e) + " is not a live sphere (stale or never added)");
  return row_of_[e.index];
}

void SphereTable::remove(Entity e) {
  std::uint32_t r = row(e);
  std::uint32_t last = static_cast<std::uint32_t>(size() - 1);
  auto move_last = [&](auto& c) {
    if (c.empty()) return;
    c[r] = c[last];
    c.pop_back();
  };
  row_of_[entity_[last]] = r;
  row_of_[e.index] = kNoRow;
  move_last(position_);
  move_last(velocity_);
  move_last(angular_velocity_);
  move_last(radius_);
  move_last(inv_mass_);
  move_last(material_);
  move_last(color_);
  move_last(still_time_);
  move_last(still_from_);
  move_last(asleep_);
  move_last(entity_);
  move_last(generation_);
}

void SphereTable::reserve(std::size_t n) {
  position_.reserve(n);
  velocity_.reserve(n);
  if (has_angular_) angular_velocity_.reserve(n);
  radius_.reserve(n);
  inv_mass_.reserve(n);
  material_.reserve(n);
  color_.reserve(n);
  still_time_.reserve(n);
  still_from_.reserve(n);
  asleep_.reserve(n);
  entity_.reserve(n);
  generation_.reserve(n);
}

void SphereTable::clear() {
  for (std::uint32_t index : entity_) row_of_[index] = kNoRow;
  position_.clear();
  velocity_.clear();
  angular_velocity_.clear();
  radius_.clear();
  inv_mass_.clear();
  material_.clear();
  color_.clear();
  still_time_.clear();
  still_from_.clear();
  asleep_.clear();
  entity_.clear();
  generation_.clear();
}

void SphereTable::set_angular(bool enabled) {
  has_angular_ = enabled;
  if (enabled) {
    angular_velocity_.assign(size(), Vec3::Zero());
  } else {
    angular_velocity_.clear();
    angular_velocity_.shrink_to_fit();
  }
}

template <class Table, class F>
void SphereTable::each_column(Table& table, F&& f) {
  f(table.position_);
  f(table.velocity_);
  f(table.angular_velocity_);
  f(table.radius_);
  f(table.inv_mass_);
  f(table.material_);
  f(table.color_);
  f(table.still_time_);
  f(table.still_from_);
  f(table.asleep_);
  f(table.entity_);
  f(table.generation_);
}

void SphereTable::permute(std::span<const std::uint32_t> new_to_old, std::size_t moving_rows) {
  const std::int64_t n = static_cast<std::int64_t>(entity_.size());
  const std::int64_t scanned = static_cast<std::int64_t>(std::min(entity_.size(), moving_rows));
  scratch_.resize(static_cast<std::size_t>(n) * kSlot);
  moved_.resize(static_cast<std::size_t>(omp_get_max_threads()));
  // The columns in rounds, each round's side by side in a row's kSlot bytes, in column order:
  // position and velocity; spin, radius, inverse mass, material (and colour without spin); the
  // rest. Row i has bytes [kSlot i, kSlot (i + 1)) of the scratch in every round, whatever the
  // columns' types, so a thread reads back just the bytes it wrote, for every round.
  struct Place {
    int round = -1;  // -1: an empty column (the spin column without spin)
    std::size_t offset = 0;
  };
  std::array<Place, kColumns> place;
  int rounds = 0, k = 0;
  std::size_t offset = kSlot;
  each_column(*this, [&](const auto& column) {
    using T = typename std::decay_t<decltype(column)>::value_type;
    static_assert(sizeof(T) <= kSlot && kSlot % alignof(T) == 0);
    Place& p = place.at(static_cast<std::size_t>(k++));  // throws if a column was added without kColumns
    if (column.empty()) return;
    offset = (offset + alignof(T) - 1) / alignof(T) * alignof(T);
    if (offset + sizeof(T) > kSlot) ++rounds, offset = 0;
    p = {rounds - 1, offset};
    offset += sizeof(T);
  });
  // One team for every column, each thread taking the same rows of each. A region per column
  // made eleven wake-ups of the team a step.
#pragma omp parallel
  {
    // A settled pit's reorder moves a tenth of the rows or less (100k pour: 4 to 13%): each
    // thread lists the rows of its share that move and copies only those, through the scratch
    // and back. A busier reorder gathers every row. Either way the columns keep their buffers,
    // so a view of one (api/ballpit.h, the Python module) stays valid across steps.
    std::vector<std::uint32_t>& mine = moved_[static_cast<std::size_t>(omp_get_thread_num())];
    mine.clear();
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < scanned; ++i)
      if (new_to_old[i] != static_cast<std::uint32_t>(i)) mine.push_back(static_cast<std::uint32_t>(i));
    std::size_t moved = 0;  // after the loop's barrier, every thread's list is complete
    for (int t = 0; t < omp_get_num_threads(); ++t) moved += moved_[static_cast<std::size_t>(t)].size();
    const bool few = 2 * moved < static_cast<std::size_t>(n);
    // Calls f(i) for this thread's rows: its list, or its static share of all n rows (the same
    // share in every loop of the region: same count, same schedule).
    auto each_row = [&](auto&& f) {
      if (few) {
        for (std::uint32_t i : mine) f(std::size_t{i});
      } else {
#pragma omp for schedule(static) nowait
        for (std::int64_t i = 0; i < n; ++i) f(static_cast<std::size_t>(i));
      }
    };
    // A round at a time: gather its columns' rows into the scratch, wait until every thread has
    // read the rows it takes from others, copy them back. The next round's gather writes only
    // the bytes this thread has just read back, so it need not wait. Objects are made in the
    // scratch by placement new: its bytes held columns of other types a round before.
    std::byte* const slots = scratch_.data();
    for (int round = 0; round < rounds; ++round) {
      int column_index = 0;
      each_column(*this, [&](auto& column) {
        using T = typename std::decay_t<decltype(column)>::value_type;
        const Place p = place[static_cast<std::size_t>(column_index++)];
        if (p.round == round)
          each_row([&](std::size_t i) { ::new (slots + i * kSlot + p.offset) T(column[new_to_old[i]]); });
      });
#pragma omp barrier
      column_index = 0;
      each_column(*this, [&](auto& column) {
        using T = typename std::decay_t<decltype(column)>::value_type;
        const Place p = place[static_cast<std::size_t>(column_index++)];
        if (p.round == round)
          each_row([&](std::size_t i) { column[i] = *std::launder(reinterpret_cast<T*>(slots + i * kSlot + p.offset)); });
      });
    }
    // Each thread maps the rows whose entity it copied back itself.
    each_row([&](std::size_t i) { row_of_[entity_[i]] = static_cast<std::uint32_t>(i); });
  }
}

SphereTable::HeldBytes SphereTable::held() const {
  HeldBytes h;
  h.columns = held_bytes(row_of_);
  each_column(*this, [&](const auto& column) { h.columns += held_bytes(column); });
  h.reorder = held_bytes(scratch_);
  for (const auto& rows : moved_) h.reorder += held_bytes(rows);
  return h;
}

std::size_t SphereTable::bytes_per_sphere() const {
  // row_of_, and permute()'s scratch: as wide as the widest column.
  std::size_t b = sizeof(std::uint32_t) + kSlot;
  each_column(*this, [&](const auto& column) {
    // The spin column exists only with spin.
    if (&column != static_cast<const void*>(&angular_velocity_) || has_angular_)
      b += sizeof(typename std::decay_t<decltype(column)>::value_type);
  });
  return b;
}

}  // namespace ballpit
