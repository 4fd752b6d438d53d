#include "engine/sphere_table.h"

#include <omp.h>

#include <cmath>
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
  auto& t = table.targets_;
  f(table.position_, t.position);
  f(table.velocity_, t.velocity);
  f(table.angular_velocity_, t.angular_velocity);
  f(table.radius_, t.radius);
  f(table.inv_mass_, t.inv_mass);
  f(table.material_, t.material);
  f(table.color_, t.color);
  f(table.still_time_, t.still_time);
  f(table.still_from_, t.still_from);
  f(table.asleep_, t.asleep);
  f(table.entity_, t.entity);
  f(table.generation_, t.generation);
}

void SphereTable::permute(std::span<const std::uint32_t> new_to_old) {
  each_column(*this, [](auto& column, auto& target) { target.resize(column.size()); });
  const std::int64_t n = static_cast<std::int64_t>(entity_.size());
  moved_.resize(static_cast<std::size_t>(omp_get_max_threads()));
  // One team for every column, each thread taking the same rows of each (nowait: no column
  // waits for another). A region per column made eleven wake-ups of the team a step.
#pragma omp parallel
  {
    // A settled pit's reorder moves a tenth of the rows or less (100k pour: 4 to 13%): each
    // thread lists the rows of its share that move and copies only those, through the
    // targets and back. A busier reorder gathers every row into the targets and copies them
    // all back: the columns keep their buffers, so a view of one (api/ballpit.h, the Python
    // module) stays valid across steps.
    std::vector<std::uint32_t>& mine = moved_[static_cast<std::size_t>(omp_get_thread_num())];
    mine.clear();
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i)
      if (new_to_old[i] != static_cast<std::uint32_t>(i)) mine.push_back(static_cast<std::uint32_t>(i));
    std::size_t moved = 0;  // after the loop's barrier, every thread's list is complete
    for (int t = 0; t < omp_get_num_threads(); ++t) moved += moved_[static_cast<std::size_t>(t)].size();
    if (2 * moved < static_cast<std::size_t>(n)) {
      each_column(*this, [&](auto& column, auto& target) {
        if (!column.empty())
          for (std::uint32_t i : mine) target[i] = column[new_to_old[i]];
      });
#pragma omp barrier
      each_column(*this, [&](auto& column, auto& target) {
        if (!column.empty())
          for (std::uint32_t i : mine) column[i] = target[i];
      });
      for (std::uint32_t i : mine) row_of_[entity_[i]] = i;
    } else {
      each_column(*this, [&](auto& column, auto& target) {
        const std::int64_t rows = static_cast<std::int64_t>(column.size());  // 0 or n
#pragma omp for schedule(static) nowait
        for (std::int64_t i = 0; i < rows; ++i) target[i] = column[new_to_old[i]];
      });
#pragma omp barrier
      // Every target is whole: copy each back, and map entities from the targets' copy.
      each_column(*this, [](auto& column, auto& target) {
        const std::int64_t rows = static_cast<std::int64_t>(column.size());
#pragma omp for schedule(static) nowait
        for (std::int64_t i = 0; i < rows; ++i) column[i] = target[i];
      });
      const std::uint32_t* entity = targets_.entity.data();
#pragma omp for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) row_of_[entity[i]] = static_cast<std::uint32_t>(i);
    }
  }
}

SphereTable::HeldBytes SphereTable::held() const {
  HeldBytes h;
  h.columns = held_bytes(row_of_);
  each_column(*this, [&](const auto& column, const auto& target) {
    h.columns += held_bytes(column);
    h.reorder += held_bytes(target);
  });
  for (const auto& rows : moved_) h.reorder += held_bytes(rows);
  return h;
}

std::size_t SphereTable::bytes_per_sphere() const {
  std::size_t b = sizeof(std::uint32_t);  // row_of_
  each_column(*this, [&](const auto& column, const auto&) {
    // Twice: the column and permute()'s target. The spin column exists only with spin.
    if (&column != static_cast<const void*>(&angular_velocity_) || has_angular_)
      b += 2 * sizeof(typename std::decay_t<decltype(column)>::value_type);
  });
  return b;
}

}  // namespace ballpit
