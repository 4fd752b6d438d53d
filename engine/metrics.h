// The error figures every report carries (shared/SCENES.md): overlap between spheres and with
// the pit, escapes, kinetic energy, top speed. Overlaps are found by a search of its own (a
// sorted cell list), not the engine's grid, so it checks the engine rather than repeating it.
#pragma once

#include <cstddef>

namespace ballpit {

class World;

struct Metrics {
  double max_penetration_r = 0.0;   // deepest sphere-sphere overlap / smaller radius
  double mean_penetration_r = 0.0;  // mean over overlapping pairs
  std::size_t overlapping_pairs = 0;
  double max_wall_penetration_r = 0.0;  // deepest overlap with floor, walls (and lid)
  std::size_t escaped = 0;              // spheres outside the pit
  double kinetic_energy_j = 0.0;        // translational + rotational (unit: J)
  double max_speed_mps = 0.0;           // (unit: m/s)
  double momentum[3] = {0, 0, 0};       // (unit: kg m/s)
};

Metrics measure(const World& world);

// Translational plus rotational (solid sphere, I = 2/5 m r^2) kinetic energy (unit: J).
double kinetic_energy(const World& world);

}  // namespace ballpit
