// The solver's own copy of the sphere state for one step: what a contact pass reads and writes,
// a 64-byte record per row, so that a batch of contacts moves each body in and out of its lanes
// with aligned loads and a transpose (systems/lanes.h), and a contact touching a body touches one
// cache line of it. (Four arrays of quads cost a contact up to four lines per body and an index
// computation per quad: a tenth of the solver's time.) The sphere table's columns are copied in
// when the step's solve begins and written back when it ends.
//
// Each quad carries a fourth value that a pass needs beside the vector:
//   velocity  v (m/s)             | mobility: inverse mass this step, 0 while asleep (1/kg)
//   spin      r w (m/s)           | pushed: 1 if a contact acted on the body this substep
//   position  x (m)               | radius (m)
//   pseudo    push-out v (m/s)    | unused
// Spin is stored as r w, the speed the spin gives the surface: a contact then needs no radius to
// turn spin into slip, nor to turn a tangential impulse into spin (systems/contact_kernel.h).
//
// kPadRows immobile bodies follow the last sphere: the lanes of a batch that carry no contact
// point at them (systems/contact_batches.h).
#pragma once

#include <cstddef>
#include <cstdint>

#include "engine/aligned_vector.h"

namespace ballpit {

struct alignas(16) Quad {
  float x, y, z, w;
};

struct alignas(64) SolverBody {
  Quad velocity;
  Quad spin;
  Quad position;
  Quad pseudo;
};

struct SolverBodies {
  static constexpr std::size_t kPadRows = 32;  // two per lane: a padding lane's a and b differ

  Column<SolverBody> body;
  std::size_t rows = 0;  // spheres, not counting the padding
  // Rows [0, awake_rows) hold every awake sphere: the rest sleep, immobile, and no pass moves
  // or stores them (systems/sleep_regions.h: RowSpans).
  std::size_t awake_rows = 0;

  // The padding bodies of lane k: far from every sphere and from each other, immobile.
  static std::uint32_t pad_a(std::size_t rows, int lane) { return static_cast<std::uint32_t>(rows + 2 * lane); }
  static std::uint32_t pad_b(std::size_t rows, int lane) { return static_cast<std::uint32_t>(rows + 2 * lane + 1); }
};

}  // namespace ballpit
