// The object Python holds as ballpit.Simulation: the C++ Simulation, and what keeps a Python
// program from breaking it across threads or through arrays that outlive a column.
// Decisions:
// - The column arrays (column_views.h) stay views for as long as they live, so a call that may
//   move a column (add_sphere, load: the sphere count or the whole state changes) is refused
//   with BufferError while any of them lives, as Python refuses to resize a bytearray while a
//   memoryview of it exists. Each array's base is a ColumnLease that counts itself here; NumPy
//   collapses a slice's base chain onto it, so a slice keeps it counted too.
// - step() runs without the GIL; `stepping` (read and written only under the GIL) makes every
//   other call from another thread refuse with RuntimeError meanwhile, instead of racing it.
//   The arrays may be read meanwhile: their memory stays where it is, the values are mid-step.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <utility>

#include "api/ballpit.h"

namespace ballpit::python {

struct PySimulation {
  explicit PySimulation(Simulation s) : sim(std::move(s)) {}

  Simulation sim;
  std::size_t live_views = 0;  // ColumnLeases alive
  bool stepping = false;       // a step() is running with the GIL released

  // Throws RuntimeError while another thread steps this Simulation.
  Simulation& idle() {
    if (stepping) throw std::runtime_error("the Simulation is stepping in another thread; wait for step() to return");
    return sim;
  }
  // As idle(), and throws BufferError while an array views the columns: `call` may move them.
  Simulation& unviewed(const char* call) {
    idle();
    if (live_views != 0)
      throw pybind11::buffer_error(std::string(call) + ": " + std::to_string(live_views) +
                                   " array(s) from positions, velocities, radii or sphere_ids still view the "
                                   "sphere columns, which this call may move; del them, then read the "
                                   "property again");
    return sim;
  }
};

}  // namespace ballpit::python
