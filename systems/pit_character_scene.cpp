#include "systems/pit_character_scene.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/character_controller.h"

namespace ballpit {

namespace {

// A lattice point is kept out of the character by this much more than touching, so no ball
// starts in a speculative contact with it (unit: ball radii).
constexpr float kSpawnClearanceR = 0.1f;

bool inside_character(const World& world, const Vec3& p, float radius) {
  const ColliderTable& c = world.colliders;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const float t = closest_segment_parameter(c.a()[k], c.b()[k], p);
    const float reach = c.radius()[k] + radius * (1.0f + kSpawnClearanceR);
    if ((p - (c.a()[k] + t * (c.b()[k] - c.a()[k]))).squaredNorm() < reach * reach) return true;
  }
  return false;
}

}  // namespace

std::vector<ScriptSegment> PitCharacterScene::scripted_path() {
  ControllerInput walk{1.0f, 0.0f, false};
  ControllerInput walk_left{1.0f, 1.0f, false};
  ControllerInput run{1.0f, 0.0f, true};
  ControllerInput idle{};
  return {{3.0f, walk}, {2.0f, walk_left}, {3.0f, run}, {2.0f, idle}};
}

Entity PitCharacterScene::build(World& world, std::shared_ptr<const Model> model) const {
  if (!model) model = import_model(character.model_path);
  const float r = pour.radius;
  pour.configure(world);

  const Entity e = add_character(world, model, character);
  const CharacterSetup& setup = world.characters.setup(static_cast<std::size_t>(world.characters.find(e)));
  world.pit.half_width = std::max(0.5f * pour.pit_width(), setup.footprint_radius + setup.controller.wall_clearance);
  RootState start;
  start.position = Vec3(0.0f, foot_clearance_r * r - setup.lowest_collider, -root_limit(setup, world.pit));
  place_character(world, e, start);

  // The pour's lattice (shared/SCENES.md: spacing 2.2 r, jitter +-0.05 r from seed 42, layer by
  // layer from y = r + 0.01 m), over this pit's width, without the points inside the character.
  const float spacing = 2.2f * r;
  const float jitter = 0.05f * r;
  const float half = world.pit.half_width;
  const float usable = 2.0f * (half - r - jitter);
  const int per_row = std::max(1, static_cast<int>(std::floor(usable / spacing)) + 1);
  const float first = -0.5f * spacing * static_cast<float>(per_row - 1);
  std::mt19937 rng(pour.seed);
  auto uniform = [&] { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); };
  world.spheres.reserve(pour.spheres);
  world.entities.reserve(pour.spheres + 1);
  std::size_t added = 0, index = 0;
  for (int layer = 0; added < pour.spheres; ++layer) {
    const float y = r + 0.01f + spacing * static_cast<float>(layer);
    for (int iz = 0; iz < per_row && added < pour.spheres; ++iz)
      for (int ix = 0; ix < per_row && added < pour.spheres; ++ix) {
        Vec3 p(first + spacing * static_cast<float>(ix), y, first + spacing * static_cast<float>(iz));
        for (int a = 0; a < 3; ++a) p[a] += (2.0f * uniform() - 1.0f) * jitter;
        if (inside_character(world, p, r)) continue;
        SphereDesc d;
        d.position = p;
        d.radius = r;
        d.mass = pour.mass;
        d.color = ball_color(index++);
        world.add_sphere(d);
        ++added;
      }
    if (y > pour.wall_height) throw Error("pit-character: the balls do not fit below the walls");
  }
  return e;
}

void PitCharacterScene::settle(World& world, Scheduler& scheduler) const {
  FixedStepLoop loop(world, scheduler);
  for (int s = 0; s < settle_steps; ++s) loop.step();
}

void PitCharacterScene::start_path(World& world, Entity who) const {
  const int i = world.characters.find(who);
  if (i < 0) throw Error("start_path: " + to_string(who) + " is not a character");
  CharacterMotion& motion = world.characters.mut_motion(static_cast<std::size_t>(i));
  motion.script = path;
  motion.script_time = 0.0f;
}

}  // namespace ballpit
