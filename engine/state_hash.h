// A hash of the full simulation state, independent of row order (spheres are visited by
// entity), so two runs agree on it exactly when every position, velocity, spin and sleep state
// is bit-identical, and with a character, its controller, animation clocks, blend, pose and
// collider rows too. Runs print it; determinism tests compare it. A world without characters
// hashes as it did before characters were hashed.
#pragma once

#include <cstdint>
#include <string>

namespace ballpit {

class World;

std::uint64_t state_hash(const World& world);
std::string hash_hex(std::uint64_t h);

}  // namespace ballpit
