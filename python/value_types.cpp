#include "python/value_types.h"

#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <string>

namespace py = pybind11;

namespace ballpit::python {

namespace {

using Triple = std::array<float, 3>;

Vector3 to_vector(const Triple& t) { return {t[0], t[1], t[2]}; }
py::tuple to_tuple(const Vector3& v) { return py::make_tuple(v.x, v.y, v.z); }

// A Vector3 member as a read-write property of 3-tuples (a sequence of 3 floats is taken).
template <class C>
void vector_property(py::class_<C>& c, const char* name, Vector3 C::*member, const char* doc) {
  c.def_property(
      name, [member](const C& s) { return to_tuple(s.*member); },
      [member](C& s, const Triple& t) { s.*member = to_vector(t); }, doc);
}

std::string vector_text(const Vector3& v) {
  return "(" + py::repr(py::float_(v.x)).cast<std::string>() + ", " + py::repr(py::float_(v.y)).cast<std::string>() +
         ", " + py::repr(py::float_(v.z)).cast<std::string>() + ")";
}

}  // namespace

void bind_value_types(py::module_& m) {
  py::class_<MaterialSpec> material(m, "MaterialSpec", "How two surfaces meet (api/ballpit.h).");
  material
      .def(py::init([](float restitution, float friction) { return MaterialSpec{restitution, friction}; }),
           py::arg("restitution") = 0.5f, py::arg("friction") = 0.5f)
      .def_readwrite("restitution", &MaterialSpec::restitution, "0..1 (unitless)")
      .def_readwrite("friction", &MaterialSpec::friction, "Coulomb coefficient (unitless)")
      .def("__repr__", [](const MaterialSpec& s) {
        return "MaterialSpec(restitution=" + py::repr(py::float_(s.restitution)).cast<std::string>() +
               ", friction=" + py::repr(py::float_(s.friction)).cast<std::string>() + ")";
      });

  py::class_<PitSpec>(m, "PitSpec", "An axis-aligned pit: floor at y = 0, walls at x, z = +-half_width.")
      .def(py::init([](float half_width, float wall_height, bool closed, const MaterialSpec& mat) {
             return PitSpec{half_width, wall_height, closed, mat};
           }),
           py::arg("half_width") = 1.0f, py::arg("wall_height") = 20.0f, py::arg("closed") = false,
           py::arg("material") = MaterialSpec{})
      .def_readwrite("half_width", &PitSpec::half_width, "(unit: m)")
      .def_readwrite("wall_height", &PitSpec::wall_height, "(unit: m)")
      .def_readwrite("closed", &PitSpec::closed)
      .def_readwrite("material", &PitSpec::material);

  py::class_<SphereSpec> sphere(m, "SphereSpec", "One sphere for Simulation.add_sphere.");
  sphere
      .def(py::init([](const Triple& position, const Triple& velocity, float radius, float mass,
                       std::uint16_t mat, std::uint32_t color) {
             return SphereSpec{to_vector(position), to_vector(velocity), radius, mass, mat, color};
           }),
           py::arg("position") = Triple{0, 0, 0}, py::arg("velocity") = Triple{0, 0, 0},
           py::arg("radius") = 0.04f, py::arg("mass") = 0.05f, py::arg("material") = 0,
           py::arg("color") = 0xffffffffu)
      .def_readwrite("radius", &SphereSpec::radius, "(unit: m) > 0")
      .def_readwrite("mass", &SphereSpec::mass, "(unit: kg) > 0")
      .def_readwrite("material", &SphereSpec::material, "what add_material returned; 0 is the pit's")
      .def_readwrite("color", &SphereSpec::color, "RGBA8, red in the low byte")
      .def("__repr__", [](const SphereSpec& s) {
        return "SphereSpec(position=" + vector_text(s.position) + ", velocity=" + vector_text(s.velocity) +
               ", radius=" + py::repr(py::float_(s.radius)).cast<std::string>() +
               ", mass=" + py::repr(py::float_(s.mass)).cast<std::string>() + ", material=" + std::to_string(s.material) + ")";
      });
  vector_property(sphere, "position", &SphereSpec::position, "(unit: m)");
  vector_property(sphere, "velocity", &SphereSpec::velocity, "(unit: m/s)");

  py::class_<ColliderSpec> collider(m, "ColliderSpec",
                                    "A kinematic sphere or capsule: infinitely heavy, moved by its velocity alone.");
  collider
      .def(py::init([](const std::string& shape, const Triple& a, const Triple& b, float radius, const Triple& velocity) {
             ColliderSpec c;
             if (shape == "sphere") c.shape = ColliderSpec::Shape::Sphere;
             else if (shape == "capsule") c.shape = ColliderSpec::Shape::Capsule;
             else throw py::value_error("ColliderSpec: shape must be 'sphere' or 'capsule', got '" + shape + "'");
             c.a = to_vector(a);
             c.b = to_vector(b);
             c.radius = radius;
             c.velocity = to_vector(velocity);
             return c;
           }),
           py::arg("shape") = "sphere", py::arg("a") = Triple{0, 0, 0}, py::arg("b") = Triple{0, 0, 0},
           py::arg("radius") = 0.05f, py::arg("velocity") = Triple{0, 0, 0})
      .def_property_readonly("shape", [](const ColliderSpec& c) {
        return c.shape == ColliderSpec::Shape::Capsule ? "capsule" : "sphere";
      })
      .def_readwrite("radius", &ColliderSpec::radius, "(unit: m) > 0");
  vector_property(collider, "a", &ColliderSpec::a, "centre, or the segment's start (unit: m)");
  vector_property(collider, "b", &ColliderSpec::b, "the segment's end; ignored for a sphere (unit: m)");
  vector_property(collider, "velocity", &ColliderSpec::velocity, "of the whole collider (unit: m/s)");
}

py::dict report_dict(const Report& r) {
  py::dict d;
  d["spheres"] = r.spheres;
  d["steps"] = r.steps;
  d["time_s"] = r.time_s;
  d["dt"] = r.dt;
  d["max_penetration_r"] = r.max_penetration_r;
  d["mean_penetration_r"] = r.mean_penetration_r;
  d["overlapping_pairs"] = r.overlapping_pairs;
  d["max_wall_penetration_r"] = r.max_wall_penetration_r;
  d["escaped"] = r.escaped;
  d["kinetic_energy_j"] = r.kinetic_energy_j;
  d["max_speed_mps"] = r.max_speed_mps;
  d["momentum"] = py::make_tuple(r.momentum[0], r.momentum[1], r.momentum[2]);
  d["state_hash"] = r.state_hash;
  d["state_hash_hex"] = r.state_hash_hex;
  return d;
}

py::dict timings_dict(const std::vector<SystemTiming>& timings) {
  py::dict d;
  for (const SystemTiming& t : timings) {
    py::dict row;
    row["mean_ms"] = t.mean_ms;
    row["median_ms"] = t.median_ms;
    row["p95_ms"] = t.p95_ms;
    row["steps"] = t.steps;
    d[py::str(t.name)] = row;
  }
  return d;
}

}  // namespace ballpit::python
