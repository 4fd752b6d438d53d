// Spheres as structure-of-arrays: one cache-aligned column per field, one row per sphere. Rows
// are reordered every step (by grid cell, so neighbours sit together in memory); the entity ->
// row map follows each reorder, so handles stay valid while rows move.
//
// A column's address is stable across steps while the sphere count does not change: a reorder
// moves rows within each column's own buffer (permute()), so a view of a column (api/ballpit.h's
// spans, the Python module's NumPy arrays) sees every step without being taken again. Adding,
// removing or clearing spheres, reserve() and set_angular() may move a column.
//
// Angular velocity is allocated only when a scene has friction: without friction nothing can
// spin a smooth sphere, and the column would cost 12 bytes a sphere for nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "engine/access.h"
#include "engine/aligned_vector.h"
#include "engine/entity.h"
#include "engine/math.h"

namespace ballpit {

struct SphereDesc {
  Vec3 position = Vec3::Zero();  // (unit: m)
  Vec3 velocity = Vec3::Zero();  // (unit: m/s)
  // Spin (unit: rad/s). Stored only in a table with angular columns (set_angular); a non-zero
  // one without them is refused, since the spin would be dropped without a word.
  Vec3 angular_velocity = Vec3::Zero();
  float radius = 0.04f;          // (unit: m)
  float mass = 0.05f;            // (unit: kg)
  std::uint16_t material = 0;    // index into World::materials
  std::uint32_t color = 0xffffffffu;  // RGBA8, red in the low byte
};

class SphereTable {
 public:
  static constexpr std::uint32_t kNoRow = 0xffffffffu;

  // Validates the description (finite position, velocity and spin, radius > 0, mass > 0, no
  // spin without angular columns) and throws ballpit::Error naming the entity and the field
  // otherwise.
  void add(Entity e, const SphereDesc& d);
  void remove(Entity e);  // swap-remove: the last row moves into the hole
  void reserve(std::size_t n);
  void clear();

  std::size_t size() const { return entity_.size(); }
  bool contains(Entity e) const;
  // Throws ballpit::Error if e is not a live sphere.
  std::uint32_t row(Entity e) const;
  Entity entity_at(std::uint32_t row) const { return {entity_[row], generation_[row]}; }
  // The row of the live sphere with this entity index, or kNoRow: for keys that hold an index
  // alone (the warm-start cache's partners, engine/contact_set.h).
  std::uint32_t row_of_index(std::uint32_t entity_index) const {
    return entity_index < row_of_.size() ? row_of_[entity_index] : kNoRow;
  }

  void set_angular(bool enabled);
  bool has_angular() const { return has_angular_; }

  // Column access. The const overloads declare a read, the mut_ ones a write; both are checked
  // against the running system's declared Access in debug builds.
  std::span<const Vec3> position() const { return read(ColumnId::SpherePosition, position_); }
  std::span<const Vec3> velocity() const { return read(ColumnId::SphereVelocity, velocity_); }
  std::span<const Vec3> angular_velocity() const {
    return read(ColumnId::SphereAngularVelocity, angular_velocity_);
  }
  std::span<const float> radius() const { return read(ColumnId::SphereRadius, radius_); }
  std::span<const float> inv_mass() const { return read(ColumnId::SphereInvMass, inv_mass_); }
  std::span<const std::uint16_t> material() const { return read(ColumnId::SphereMaterial, material_); }
  std::span<const std::uint32_t> color() const { return read(ColumnId::SphereColor, color_); }
  std::span<const float> still_time() const { return read(ColumnId::SphereSleep, still_time_); }
  std::span<const Vec3> still_from() const { return read(ColumnId::SphereSleep, still_from_); }
  std::span<const std::uint8_t> asleep() const { return read(ColumnId::SphereSleep, asleep_); }
  std::span<const std::uint32_t> entity_index() const { return read(ColumnId::SphereRows, entity_); }

  std::span<Vec3> mut_position() { return write(ColumnId::SpherePosition, position_); }
  std::span<Vec3> mut_velocity() { return write(ColumnId::SphereVelocity, velocity_); }
  std::span<Vec3> mut_angular_velocity() {
    return write(ColumnId::SphereAngularVelocity, angular_velocity_);
  }
  std::span<float> mut_radius() { return write(ColumnId::SphereRadius, radius_); }
  std::span<float> mut_inv_mass() { return write(ColumnId::SphereInvMass, inv_mass_); }
  std::span<std::uint32_t> mut_color() { return write(ColumnId::SphereColor, color_); }
  std::span<float> mut_still_time() { return write(ColumnId::SphereSleep, still_time_); }
  std::span<Vec3> mut_still_from() { return write(ColumnId::SphereSleep, still_from_); }
  std::span<std::uint8_t> mut_asleep() { return write(ColumnId::SphereSleep, asleep_); }

  // Moves row new_to_old[i] to row i for every column, and updates the entity -> row map.
  // new_to_old must be a permutation of [0, size()), the identity from row `moving_rows` on
  // (a settled pit's sleepers keep their rows: those are not even read). Each column keeps its
  // buffer.
  void permute(std::span<const std::uint32_t> new_to_old, std::size_t moving_rows = SIZE_MAX);

  // Bytes held per sphere by the columns, permute()'s scratch included (for the memory report).
  std::size_t bytes_per_sphere() const;
  // Bytes the columns (with the entity -> row map) and permute()'s scratch hold now.
  struct HeldBytes {
    std::size_t columns = 0, reorder = 0;
  };
  HeldBytes held() const;

 private:
  template <class T>
  static std::span<const T> read(ColumnId id, const Column<T>& c) {
    check_access(id, false);
    return {c.data(), c.size()};
  }
  template <class T>
  static std::span<T> write(ColumnId id, Column<T>& c) {
    check_access(id, true);
    return {c.data(), c.size()};
  }
  // Calls f(column) for every column of `table` (const or not).
  template <class Table, class F>
  static void each_column(Table& table, F&& f);

  Column<Vec3> position_;
  Column<Vec3> velocity_;
  Column<Vec3> angular_velocity_;  // empty unless has_angular_
  Column<float> radius_;
  Column<float> inv_mass_;
  Column<std::uint16_t> material_;
  Column<std::uint32_t> color_;
  Column<float> still_time_;       // seconds spent still (systems/sleeping.h) (unit: s)
  Column<Vec3> still_from_;        // where the sphere was when its still time began (unit: m)
  Column<std::uint8_t> asleep_;
  Column<std::uint32_t> entity_;      // entity index of each row
  Column<std::uint32_t> generation_;  // entity generation of each row
  std::vector<std::uint32_t> row_of_;  // entity index -> row, kNoRow if not a sphere
  bool has_angular_ = false;

  // permute()'s scratch: the columns' rows are gathered here and copied back, so a reorder every
  // step neither allocates nor zeroes a column and leaves each column where it was. One buffer
  // of 24 bytes a row, taking the columns in three rounds, not a target per column: the targets
  // cost 68 bytes a sphere, as much as the columns (issue 42; 100k pour, 1,403 B/sphere peak).
  // A column a round, through 12 bytes a row, waited for the team eleven times a reorder: with
  // 2 threads on 2 busy cores each wait could cost a time slice (test_determinism took 40 s, not
  // 3). (Swapping a column with its target instead saved the copy back but moved every column
  // every step, so no view of one outlived a step.)
  static constexpr std::size_t kSlot = 2 * sizeof(Vec3);  // scratch bytes a row
  static constexpr int kColumns = 12;  // each_column's count: a new column must raise it
  Column<std::byte> scratch_;
  std::vector<std::vector<std::uint32_t>> moved_;  // permute(): each thread's rows that move
};

}  // namespace ballpit
