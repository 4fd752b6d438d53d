// The canonical "pour" scene of shared/SCENES.md, in one place so tests, benchmarks, the
// headless runner and the Bullet comparison all build exactly the same scene.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/math.h"

namespace ballpit {

class World;
struct Population;

struct PourScene {
  std::size_t spheres = 10000;
  float radius = 0.04f;   // (unit: m)
  float mass = 0.05f;     // (unit: kg)
  float restitution = 0.5f;
  float friction = 0.5f;
  float wall_height = 20.0f;  // (unit: m)
  std::uint32_t seed = 42;
  float dt = 1.0f / 60.0f;    // (unit: s)
  int steps = 600;

  // L = sqrt(N * 5.6e-4): settled depth about 0.8 m.
  float pit_width() const;
  // Jittered cubic lattice, spacing 2.2 r, jitter +-0.05 r per axis, layer by layer from
  // y = r + 0.01 m up.
  std::vector<Vec3> initial_positions() const;
  // The scene's settings without its spheres: pit (sized by the pour formula), material,
  // gravity, step, spin state, sleeping off (as measured). Scenes built on the pour (the
  // character's) start from this.
  void configure(World& world) const;
  // Fills an empty world: configure(), then the spheres.
  void build(World& world) const;
  // The pour's balls as a scene-file population (engine/populations.h): placed from `seed`
  // by add_populations, they are exactly the spheres build() adds.
  Population population() const;
};

// Ball-pit colours, picked by index so every run colours the same sphere the same way.
std::uint32_t ball_color(std::uint64_t index);

}  // namespace ballpit
