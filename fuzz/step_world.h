// Runs a few steps of a world a fuzz target has just loaded or built, as `ballpit run` would:
// the physics pipeline on one thread, behind the NaN guard. A scene or snapshot the engine
// accepts must also step without undefined behaviour; a step that goes non-finite ends in
// the guard's NonFiniteState, a ballpit::Error, as in the app.
#pragma once

#include <cstddef>

namespace ballpit {
class World;
}

namespace ballpit::fuzz {

// Worlds with more spheres than this are not stepped: the fuzzer's time is better spent on
// inputs than on physics, and a few spheres reach every branch a thousand do.
inline constexpr std::size_t kMaxSteppedSpheres = 64;

// Steps `world` `steps` times if it has at most kMaxSteppedSpheres spheres.
void step_small_world(World& world, int steps);

}  // namespace ballpit::fuzz
