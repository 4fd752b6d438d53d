#include "engine/access.h"

#include <string>

#include "engine/error.h"

namespace ballpit {

namespace {
thread_local const Access* t_access = nullptr;
thread_local std::string_view t_system;
}  // namespace

std::string_view column_name(ColumnId c) {
  switch (c) {
    case ColumnId::SpherePosition: return "sphere.position";
    case ColumnId::SphereVelocity: return "sphere.velocity";
    case ColumnId::SphereAngularVelocity: return "sphere.angular_velocity";
    case ColumnId::SphereRadius: return "sphere.radius";
    case ColumnId::SphereInvMass: return "sphere.inv_mass";
    case ColumnId::SphereMaterial: return "sphere.material";
    case ColumnId::SphereColor: return "sphere.color";
    case ColumnId::SphereSleep: return "sphere.sleep";
    case ColumnId::SphereRows: return "sphere.rows";
    case ColumnId::Colliders: return "colliders";
    case ColumnId::CharacterPose: return "character.pose";
    case ColumnId::CharacterController: return "character.controller";
    case ColumnId::Grid: return "grid";
    case ColumnId::Contacts: return "contacts";
    case ColumnId::Gravity: return "gravity";
    case ColumnId::StepCounter: return "step_counter";
    case ColumnId::Count: break;
  }
  return "?";
}

ColumnSet ColumnSet::all_sphere_columns() {
  return {ColumnId::SpherePosition, ColumnId::SphereVelocity, ColumnId::SphereAngularVelocity,
          ColumnId::SphereRadius,   ColumnId::SphereInvMass,  ColumnId::SphereMaterial,
          ColumnId::SphereColor,    ColumnId::SphereSleep,    ColumnId::SphereRows};
}

AccessScope::AccessScope(const Access* access, std::string_view system_name)
    : previous_(t_access), previous_name_(t_system) {
  t_access = access;
  t_system = system_name;
}

AccessScope::~AccessScope() {
  t_access = previous_;
  t_system = previous_name_;
}

void check_access(ColumnId column, bool write) {
#ifndef NDEBUG
  if (t_access == nullptr) return;
  bool ok = write ? t_access->writes.has(column)
                  : (t_access->reads.has(column) || t_access->writes.has(column));
  if (!ok) {
    throw Error("system '" + std::string(t_system) + "' " + (write ? "writes" : "reads") + " " +
                std::string(column_name(column)) + " without declaring it");
  }
#else
  (void)column;
  (void)write;
#endif
}

}  // namespace ballpit
