#include "python/column_views.h"

#include <cstdint>
#include <span>
#include <string>

namespace py = pybind11;

namespace ballpit::python {

namespace {

// The base of every column array: holds the Simulation, and counts itself in live_views while
// any array (or slice of one) that views the columns lives.
struct ColumnLease {
  explicit ColumnLease(py::object owner) : simulation(std::move(owner)) {
    simulation.cast<PySimulation&>().live_views += 1;
  }
  ColumnLease(const ColumnLease&) = delete;
  ColumnLease& operator=(const ColumnLease&) = delete;
  ~ColumnLease() { simulation.cast<PySimulation&>().live_views -= 1; }
  py::object simulation;
};

template <class T>
py::array view(py::object self, std::span<const T> column, std::size_t rows, std::size_t width) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(width * sizeof(T))};
  if (width > 1) {
    shape.push_back(static_cast<py::ssize_t>(width));
    strides.push_back(static_cast<py::ssize_t>(sizeof(T)));
  }
  // An empty column has no buffer: NumPy's own empty array then, which views nothing.
  if (column.empty()) return py::array(py::dtype::of<T>(), shape, strides);
  py::object lease = py::cast(new ColumnLease(std::move(self)), py::return_value_policy::take_ownership);
  py::array a(py::dtype::of<T>(), shape, strides, column.data(), lease);
  // Read-only; NumPy refuses to make it writeable again, since its base exposes no buffer.
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

}  // namespace

void bind_column_lease(py::module_& m) {
  py::class_<ColumnLease>(m, "ColumnLease",
                          "The base of a column array: keeps its Simulation alive, and its sphere "
                          "columns where they are, while the array lives.")
      .def_property_readonly("simulation", [](const ColumnLease& l) { return l.simulation; });
}

py::array column_view(py::object self, Column column) {
  const Simulation& sim = self.cast<PySimulation&>().idle();
  const std::size_t n = sim.sphere_count();
  switch (column) {
    case Column::Positions: return view(std::move(self), sim.positions(), n, 3);
    case Column::Velocities: return view(std::move(self), sim.velocities(), n, 3);
    case Column::Radii: return view(std::move(self), sim.radii(), n, 1);
    case Column::SphereIds: return view(std::move(self), sim.sphere_ids(), n, 1);
  }
  throw std::logic_error("column_view: unknown column");
}

std::vector<float> rows_of_three(py::handle values, std::size_t rows, const char* what) {
  const py::module_ np = py::module_::import("numpy");
  py::array a = np.attr("asarray")(values);
  const char kind = a.dtype().kind();
  if (kind != 'f')
    throw py::type_error(std::string(what) + " must be an array of floating-point numbers (float32 or float64), got dtype " +
                         py::str(a.dtype()).cast<std::string>());
  if (a.ndim() != 2 || a.shape(1) != 3 || static_cast<std::size_t>(a.shape(0)) != rows) {
    std::string shape = py::str(py::tuple(a.attr("shape"))).cast<std::string>();
    throw py::value_error(std::string(what) + " must have shape (" + std::to_string(rows) +
                          ", 3): x, y, z of each of the Simulation's rows; got shape " + shape);
  }
  // float32, C order: a copy only where the dtype or layout differs.
  auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!f) throw py::error_already_set();
  return std::vector<float>(f.data(), f.data() + 3 * rows);
}

}  // namespace ballpit::python
