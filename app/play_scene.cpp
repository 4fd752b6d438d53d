#include "app/play_scene.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "engine/pour_scene.h"
#include "engine/world.h"
#include "systems/pit_character_scene.h"

namespace ballpit {

float PlayScene::half_width(float footprint_radius, float wall_clearance) const {
  const PourScene pour{.spheres = spheres};
  return std::max(0.5f * pour.pit_width(), footprint_radius + wall_clearance + walk_room);
}

Entity PlayScene::build(World& world, std::shared_ptr<const Model> model) const {
  const PourScene pour{.spheres = spheres};
  // The controller clamps the root against the pit, so the pit must exist first: spawn in a
  // pit as wide as the pour formula, then widen it to what the fitted footprint needs.
  pour.configure(world);
  world.solver.sleeping = sleeping;
  const Entity spawned = model ? add_character(world, std::move(model), character) : add_character(world, character);
  const CharacterSetup& setup = world.characters.setup(0);
  world.pit.half_width = half_width(setup.footprint_radius, setup.controller.wall_clearance);
  place_character(world, spawned, standing_root(setup, character.heading));

  world.spheres.reserve(spheres);
  world.entities.reserve(spheres + 1);
  place_balls(world, spheres, 0.0f, pour.seed, 0);
  return spawned;
}

RootState standing_root(const CharacterSetup& setup, float heading) {
  // The canonical pit-character scene's rule, so a hoof never pins a ball to the floor.
  static const PitCharacterScene canonical;
  RootState root;
  root.position = Vec3(0.0f, canonical.foot_clearance_r * canonical.pour.radius - setup.lowest_collider, 0.0f);
  root.heading = heading;
  return root;
}

std::size_t place_balls(World& world, std::size_t count, float floor_y, std::uint32_t seed,
                        std::uint64_t first_color_index) {
  const PourScene pour;  // the canonical ball and lattice
  const float r = pour.radius;
  const float spacing = 2.2f * r;
  const float jitter = 0.05f * r;
  const float half = world.pit.half_width;
  const float usable = 2.0f * (half - r - jitter);
  const int per_row = std::max(1, static_cast<int>(std::floor(usable / spacing)) + 1);
  const float first = -0.5f * spacing * static_cast<float>(per_row - 1);
  std::mt19937 rng(seed);
  // Raw bits, as the pour scene does, so the jitter is the same on every standard library.
  auto uniform = [&] { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); };

  std::span<const Vec3> ca = world.colliders.a();
  std::span<const Vec3> cb = world.colliders.b();
  std::span<const float> cr = world.colliders.radius();
  // A ball this close to a collider's surface is skipped: the lattice jitter plus a margin
  // the solver's first step need not resolve (unit: m).
  const float margin = r + 2.0f * jitter;
  auto touches_collider = [&](const Vec3& p) {
    for (std::size_t k = 0; k < ca.size(); ++k) {
      const float t = closest_segment_parameter(ca[k], cb[k], p);
      const Vec3 q = ca[k] + t * (cb[k] - ca[k]);
      if ((p - q).squaredNorm() < (cr[k] + margin) * (cr[k] + margin)) return true;
    }
    return false;
  };

  std::size_t placed = 0;
  for (int layer = 0; placed < count; ++layer) {
    const float y = floor_y + r + 0.01f + spacing * static_cast<float>(layer);
    if (y > world.pit.wall_height - r) break;
    for (int iz = 0; iz < per_row && placed < count; ++iz) {
      for (int ix = 0; ix < per_row && placed < count; ++ix) {
        Vec3 p(first + spacing * static_cast<float>(ix), y, first + spacing * static_cast<float>(iz));
        for (int a = 0; a < 3; ++a) p[a] += (2.0f * uniform() - 1.0f) * jitter;
        if (touches_collider(p)) continue;
        SphereDesc d;
        d.position = p;
        d.radius = r;
        d.mass = pour.mass;
        d.color = ball_color(first_color_index + placed);
        world.add_sphere(d);
        ++placed;
      }
    }
  }
  return placed;
}

}  // namespace ballpit
