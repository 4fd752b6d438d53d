// The API's value types in Python: MaterialSpec, PitSpec, SphereSpec and ColliderSpec as classes
// with keyword constructors (vectors as 3-tuples of floats), and the report and timings as
// dicts. The engine validates the values when they are used (add_sphere names the sphere and
// the field), so these only carry them.
#pragma once

#include <pybind11/pybind11.h>

#include <vector>

#include "api/ballpit.h"

namespace ballpit::python {

void bind_value_types(pybind11::module_& m);

// Report's fields by their C++ names; momentum as a 3-tuple.
pybind11::dict report_dict(const Report& r);
// {system name: {"mean_ms", "median_ms", "p95_ms", "steps"}}, in pipeline order.
pybind11::dict timings_dict(const std::vector<SystemTiming>& timings);

}  // namespace ballpit::python
