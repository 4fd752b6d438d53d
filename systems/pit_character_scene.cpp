#include "systems/pit_character_scene.h"

#include <algorithm>
#include <span>

#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/populations.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/character_controller.h"

namespace ballpit {

namespace {

// A lattice point is kept out of the character by this much more than touching, so no ball
// starts in a speculative contact with it (unit: ball radii).
constexpr float kSpawnClearanceR = 0.1f;

}  // namespace

bool inside_character(const World& world, const Vec3& p, float radius) {
  const ColliderTable& c = world.colliders;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const float t = closest_segment_parameter(c.a()[k], c.b()[k], p);
    const float reach = c.radius()[k] + radius * (1.0f + kSpawnClearanceR);
    if ((p - (c.a()[k] + t * (c.b()[k] - c.a()[k]))).squaredNorm() < reach * reach) return true;
  }
  return false;
}

std::vector<ScriptSegment> PitCharacterScene::scripted_path() {
  return SceneCharacter::default_path();  // one definition, shared with the scene files
}

Entity spawn_pit_character(World& world, std::shared_ptr<const Model> model, const CharacterDesc& desc,
                           float clearance) {
  const Entity e = add_character(world, std::move(model), desc);
  const CharacterSetup& setup = world.characters.setup(static_cast<std::size_t>(world.characters.find(e)));
  world.pit.half_width = std::max(world.pit.half_width, setup.footprint_radius + setup.controller.wall_clearance);
  RootState start;
  start.position = Vec3(0.0f, clearance - setup.lowest_collider, -root_limit(setup, world.pit));
  place_character(world, e, start);
  return e;
}

Entity PitCharacterScene::build(World& world, std::shared_ptr<const Model> model) const {
  if (!model) model = load_model(character.model_path);
  pour.configure(world);
  const Entity e = spawn_pit_character(world, std::move(model), character, foot_clearance_r * pour.radius);
  // The pour's lattice (shared/SCENES.md: spacing 2.2 r, jitter +-0.05 r from seed 42, layer by
  // layer from y = r + 0.01 m), over this pit's width, without the points inside the character.
  const Population balls = pour.population();
  add_populations(world, std::span<const Population>(&balls, 1), pour.seed, "pit-character",
                  [&world](const Vec3& p, float r) { return inside_character(world, p, r); });
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
