// What a system declares it touches. Every sphere field, every table and every shared resource
// (grid, contact set, gravity...) has a ColumnId; a system's Access lists the ones it reads and
// writes. The scheduler orders two systems iff their accesses conflict, and in debug builds the
// tables check each column request against the running system's declaration.
#pragma once

#include <bitset>
#include <cstdint>
#include <initializer_list>
#include <string_view>

namespace ballpit {

enum class ColumnId : std::uint8_t {
  // sphere table, one per SoA field
  SpherePosition,
  SphereVelocity,
  SphereAngularVelocity,
  SphereRadius,
  SphereInvMass,
  SphereMaterial,
  SphereColor,
  SphereSleep,
  SphereRows,  // row order and the entity <-> row maps (written by anything that reorders)
  // joint collider table
  Colliders,
  // characters: skeleton pose, clip state, controller
  CharacterPose,
  CharacterController,
  // shared resources
  Grid,
  Contacts,
  Gravity,
  StepCounter,
  Count
};

std::string_view column_name(ColumnId c);

class ColumnSet {
 public:
  ColumnSet() = default;
  ColumnSet(std::initializer_list<ColumnId> ids) {
    for (ColumnId id : ids) add(id);
  }
  ColumnSet& add(ColumnId id) {
    bits_.set(static_cast<std::size_t>(id));
    return *this;
  }
  bool has(ColumnId id) const { return bits_.test(static_cast<std::size_t>(id)); }
  bool intersects(const ColumnSet& o) const { return (bits_ & o.bits_).any(); }
  ColumnSet operator|(const ColumnSet& o) const {
    ColumnSet r;
    r.bits_ = bits_ | o.bits_;
    return r;
  }
  bool empty() const { return bits_.none(); }

  // Every field of the sphere table: what a reorder must declare as written.
  static ColumnSet all_sphere_columns();

 private:
  std::bitset<static_cast<std::size_t>(ColumnId::Count)> bits_;
};

struct Access {
  ColumnSet reads;
  ColumnSet writes;

  // Two systems conflict when one writes what the other reads or writes.
  bool conflicts_with(const Access& o) const {
    return writes.intersects(o.reads | o.writes) || o.writes.intersects(reads);
  }
};

// Debug-build check that the running system declared the column it asks for. The scheduler
// installs the running system's Access for its thread; outside a scheduled system (tests,
// setup code) nothing is installed and every request is allowed.
class AccessScope {
 public:
  AccessScope(const Access* access, std::string_view system_name);
  ~AccessScope();
  AccessScope(const AccessScope&) = delete;
  AccessScope& operator=(const AccessScope&) = delete;

 private:
  const Access* previous_;
  std::string_view previous_name_;
};

void check_access(ColumnId column, bool write);

}  // namespace ballpit
