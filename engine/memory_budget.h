// How many spheres a run may ask for: a run that would not fit in memory is refused before it
// allocates anything, with the estimate in the message, instead of swapping the machine to a
// halt or being killed half-way through a long study.
#pragma once

#include <cstddef>
#include <string>

namespace ballpit {

// Peak memory a sphere costs in a pour run, all of it: columns, grid, contacts, warm-start
// cache, the NaN guard's last good copy and the allocator's slack (unit: bytes). Measured as
// peak RSS / N of a settled 100k pour (850 B), rounded up for headroom.
inline constexpr double kPeakBytesPerSphere = 1000.0;

// The memory a run may plan on (unit: bytes): the machine's physical memory, or
// BALLPIT_MEMORY_LIMIT_MB when it is set (a shared machine's share, or a test of the refusal).
double memory_budget_bytes();

// Throws ballpit::Error if `spheres` would need more than the budget. The message names the
// flag, the estimate and the budget, and always contains "needs about" (scripts look for it).
void refuse_if_too_big(std::size_t spheres, const std::string& flag = "--spheres");

}  // namespace ballpit
