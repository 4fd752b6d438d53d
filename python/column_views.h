// NumPy arrays over the engine's sphere columns, and the checks on arrays written back.
// Reading makes no copy: positions() is an (N, 3) float32 array whose data is the engine's own
// column, read-only, whose base (a ColumnLease) keeps the Simulation alive. A column's address
// holds across steps while the sphere count does not change (engine/sphere_table.h), so an
// array taken once sees every step. Writing copies, through Simulation::set_positions and
// set_velocities, which validate every row.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "python/py_simulation.h"

namespace ballpit::python {

// Registers ColumnLease, the arrays' base (ballpit_module.cpp calls it before the Simulation).
void bind_column_lease(pybind11::module_& m);

enum class Column { Positions, Velocities, Radii, SphereIds };

// A read-only array viewing `column` of `self` (a PySimulation).
pybind11::array column_view(pybind11::object self, Column column);

// The rows of an (N, 3) array of floats, as float32, x, y, z of each row: TypeError for what is
// not an array of floating-point numbers, ValueError for another shape than (rows, 3). The
// values are the engine's to check (it names the row that is not finite).
std::vector<float> rows_of_three(pybind11::handle values, std::size_t rows, const char* what);

}  // namespace ballpit::python
