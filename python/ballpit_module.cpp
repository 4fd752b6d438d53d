// The Python module `ballpit`: api/ballpit.h's Simulation for Python (docs/api.md, "Use it from
// Python"). Reads are NumPy arrays that view the engine's columns (column_views.h); writes go
// through setters that validate; step() releases the GIL.
// Errors: the engine's ballpit::Error becomes ValueError with the engine's message; a wrong
// type or shape is TypeError or ValueError; nothing a script passes may crash the interpreter.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <string>
#include <vector>

#include "api/ballpit.h"
#include "python/column_views.h"
#include "python/py_simulation.h"
#include "python/value_types.h"

namespace py = pybind11;
using namespace ballpit;
using ballpit::python::Column;
using ballpit::python::PySimulation;

namespace {

using Triple = std::array<float, 3>;

SimulationOptions options(int threads, const std::string& model_probe) {
  SimulationOptions o;
  o.threads = threads;
  if (!model_probe.empty()) o.model_probe = model_probe;
  return o;
}

// Runs `make` (which builds a Simulation from files: a character scene settles for a while)
// without the GIL.
template <class F>
PySimulation make_released(F&& make) {
  py::gil_scoped_release release;
  return PySimulation(make());
}

// The steps, one at a time without the GIL, checking between steps for a signal (Ctrl-C raises
// KeyboardInterrupt after the step it came in).
void step(PySimulation& s, int steps) {
  Simulation& sim = s.idle();
  if (steps < 0) throw Error("step: steps must be >= 0, got " + std::to_string(steps));
  s.stepping = true;
  struct Done {
    PySimulation& s;
    ~Done() { s.stepping = false; }  // under the GIL again: release's scope has ended
  } done{s};
  for (int i = 0; i < steps; ++i) {
    {
      py::gil_scoped_release release;
      sim.step(1);
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

}  // namespace

PYBIND11_MODULE(ballpit, m) {
  m.doc() = "ballpit: a ball-pit physics engine (api/ballpit.h's Simulation; docs/api.md)";
  m.attr("__version__") = version();

  // ballpit::Error: bad input, named by the engine.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  python::bind_value_types(m);
  python::bind_column_lease(m);

  py::class_<PySimulation>(m, "Simulation",
                           "A pit of spheres: build it (a scene, a snapshot, or in code), step it, read it.\n"
                           "positions, velocities, radii and sphere_ids are read-only NumPy arrays over the\n"
                           "engine's columns: taken once, they show every step (rows are reordered by grid\n"
                           "cell each step; sphere_ids says which sphere each row is).")
      .def(py::init([](const PitSpec& pit, int threads, const std::string& model_probe) {
             return PySimulation(Simulation(pit, options(threads, model_probe)));
           }),
           py::arg("pit") = PitSpec{}, py::kw_only(), py::arg("threads") = 0, py::arg("model_probe") = "",
           "An empty pit to fill in code: gravity -9.81 m/s^2 along y, dt 1/60 s, sleeping off.")
      .def_static(
          "from_scene",
          [](const std::string& scene, const std::vector<std::string>& overrides, int threads,
             const std::string& model_probe) {
            return make_released([&] { return Simulation::from_scene(scene, overrides, options(threads, model_probe)); });
          },
          py::arg("scene"), py::arg("overrides") = std::vector<std::string>{}, py::kw_only(), py::arg("threads") = 0,
          py::arg("model_probe") = "",
          "A scene file or built-in scene ('pour', 'pit-character') with `ballpit run --set` overrides\n"
          "(['populations.0.count=2000']).")
      .def_static(
          "from_snapshot",
          [](const std::string& path, int threads, const std::string& model_probe) {
            return make_released([&] { return Simulation::from_snapshot(path, options(threads, model_probe)); });
          },
          py::arg("path"), py::kw_only(), py::arg("threads") = 0, py::arg("model_probe") = "",
          "The state a snapshot file holds (save()).")

      // Building in code.
      .def("add_material", [](PySimulation& s, const MaterialSpec& mat) { return s.idle().add_material(mat); },
           py::arg("material"), "Returns the material's index for SphereSpec.material.")
      .def("add_sphere", [](PySimulation& s, const SphereSpec& sphere) { return s.unviewed("add_sphere").add_sphere(sphere); },
           py::arg("sphere"), "Returns the sphere's id (see sphere_ids).")
      .def("add_collider", [](PySimulation& s, const ColliderSpec& c) { return s.idle().add_collider(c); },
           py::arg("collider"), "Returns the collider's index, 0, 1, ... in the order added.")
      .def("set_collider_velocity",
           [](PySimulation& s, std::uint32_t collider, const Triple& v) {
             s.idle().set_collider_velocity(collider, {v[0], v[1], v[2]});
           },
           py::arg("collider"), py::arg("velocity"))

      // Settings: set_* validate; the properties read.
      .def("set_gravity", [](PySimulation& s, const Triple& g) { s.idle().set_gravity({g[0], g[1], g[2]}); },
           py::arg("gravity"), "(unit: m/s^2); wakes every sleeper")
      .def_property_readonly("gravity", [](PySimulation& s) {
        const Vector3 g = s.idle().gravity();
        return py::make_tuple(g.x, g.y, g.z);
      })
      .def("set_dt", [](PySimulation& s, float dt) { s.idle().set_dt(dt); }, py::arg("dt"), "the fixed step (unit: s)")
      .def_property_readonly("dt", [](PySimulation& s) { return s.idle().dt(); })
      .def("set_substeps", [](PySimulation& s, int n) { s.idle().set_substeps(n); }, py::arg("substeps"), "1..64")
      .def_property_readonly("substeps", [](PySimulation& s) { return s.idle().substeps(); })
      .def("set_sleeping", [](PySimulation& s, bool on) { s.idle().set_sleeping(on); }, py::arg("sleeping"))
      .def_property_readonly("sleeping", [](PySimulation& s) { return s.idle().sleeping(); })

      // Running.
      .def("step", &step, py::arg("steps") = 1, "Takes `steps` fixed steps of dt, without the GIL.")
      .def_property_readonly("step_count", [](PySimulation& s) { return s.idle().step_count(); })
      .def_property_readonly("time", [](PySimulation& s) { return s.idle().time(); }, "step_count x dt (unit: s)")

      // Reading, without copying.
      .def_property_readonly("sphere_count", [](PySimulation& s) { return s.idle().sphere_count(); })
      .def_property_readonly("collider_count", [](PySimulation& s) { return s.idle().collider_count(); })
      .def_property_readonly(
          "positions", [](py::object self) { return python::column_view(std::move(self), Column::Positions); },
          "(N, 3) float32, read-only view of the engine's column (unit: m)")
      .def_property_readonly(
          "velocities", [](py::object self) { return python::column_view(std::move(self), Column::Velocities); },
          "(N, 3) float32, read-only view of the engine's column (unit: m/s)")
      .def_property_readonly(
          "radii", [](py::object self) { return python::column_view(std::move(self), Column::Radii); },
          "(N,) float32, read-only view (unit: m)")
      .def_property_readonly(
          "sphere_ids", [](py::object self) { return python::column_view(std::move(self), Column::SphereIds); },
          "(N,) uint32, read-only view: the id add_sphere returned (or the scene's index) of each row")

      // Writing, validated.
      .def("set_positions",
           [](PySimulation& s, py::handle xyz) {
             Simulation& sim = s.idle();
             sim.set_positions(python::rows_of_three(xyz, sim.sphere_count(), "set_positions: positions"));
           },
           py::arg("positions"), "(N, 3) floats in row order (unit: m); every value finite. Wakes every sleeper.")
      .def("set_velocities",
           [](PySimulation& s, py::handle xyz) {
             Simulation& sim = s.idle();
             sim.set_velocities(python::rows_of_three(xyz, sim.sphere_count(), "set_velocities: velocities"));
           },
           py::arg("velocities"), "(N, 3) floats in row order (unit: m/s); every value finite. Wakes every sleeper.")

      // Measuring.
      .def("report", [](PySimulation& s) { return python::report_dict(s.idle().report()); },
           "The figures of `ballpit run`'s report line, measured now (O(N log N)).")
      .def_property_readonly("state_hash", [](PySimulation& s) { return s.idle().state_hash(); })
      .def("timings", [](PySimulation& s) { return python::timings_dict(s.idle().timings()); },
           "{system: {mean_ms, median_ms, p95_ms, steps}} since the first step or reset_timings()")
      .def("timings_table", [](PySimulation& s) { return s.idle().timings_table(); })
      .def("reset_timings", [](PySimulation& s) { s.idle().reset_timings(); })

      // Snapshots.
      .def("save", [](PySimulation& s, const std::string& path) { s.idle().save(path); }, py::arg("path"))
      .def("load", [](PySimulation& s, const std::string& path) { s.unviewed("load").load(path); }, py::arg("path"),
           "Replaces the whole state with the file's; on error nothing changes.");
}
