#include "engine/pour_scene.h"

#include <cmath>
#include <random>

#include "engine/populations.h"
#include "engine/world.h"

namespace ballpit {

float PourScene::pit_width() const { return std::sqrt(static_cast<float>(spheres) * 5.6e-4f); }

std::vector<Vec3> PourScene::initial_positions() const {
  const float spacing = 2.2f * radius;
  const float jitter = 0.05f * radius;
  const float half = 0.5f * pit_width();
  // Lattice points whose jittered sphere stays inside the walls, centred in the pit.
  const float usable = 2.0f * (half - radius - jitter);
  const int per_row = std::max(1, static_cast<int>(std::floor(usable / spacing)) + 1);
  const float first = -0.5f * spacing * static_cast<float>(per_row - 1);

  std::mt19937 rng(seed);
  // mt19937's output is fully specified; std::uniform_real_distribution is not, so the
  // jitter is derived from raw bits to stay identical across standard libraries.
  auto uniform = [&] { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); };

  std::vector<Vec3> out;
  out.reserve(spheres);
  for (int layer = 0; out.size() < spheres; ++layer) {
    float y = radius + 0.01f + spacing * static_cast<float>(layer);
    for (int iz = 0; iz < per_row && out.size() < spheres; ++iz) {
      for (int ix = 0; ix < per_row && out.size() < spheres; ++ix) {
        Vec3 p(first + spacing * static_cast<float>(ix), y, first + spacing * static_cast<float>(iz));
        for (int a = 0; a < 3; ++a) p[a] += (2.0f * uniform() - 1.0f) * jitter;
        out.push_back(p);
      }
    }
  }
  return out;
}

void PourScene::configure(World& world) const {
  world.pit.half_width = 0.5f * pit_width();
  world.pit.wall_height = wall_height;
  world.pit.closed = false;
  world.pit.material = {restitution, friction};
  world.materials.assign(1, Material{restitution, friction});
  world.set_gravity(Vec3(0.0f, -9.81f, 0.0f));
  world.set_step(dt);
  world.solver.sleeping = false;
  world.enable_angular(friction > 0.0f);
}

void PourScene::build(World& world) const {
  configure(world);
  std::vector<Vec3> positions = initial_positions();
  world.spheres.reserve(positions.size());
  world.entities.reserve(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    SphereDesc d;
    d.position = positions[i];
    d.radius = radius;
    d.mass = mass;
    d.color = ball_color(i);
    world.add_sphere(d);
  }
}

Population PourScene::population() const {
  Population p;
  p.count = spheres;
  p.radius.value = radius;
  p.mass = mass;
  p.material = {restitution, friction};
  return p;  // the ball-pit palette, on the jittered lattice from the floor: the defaults
}

std::uint32_t ball_color(std::uint64_t index) { return palette_color(index, ball_palette()); }

}  // namespace ballpit
