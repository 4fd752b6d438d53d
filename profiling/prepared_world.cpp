#include "profiling/prepared_world.h"

#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "engine/fixed_step_loop.h"
#include "engine/pour_scene.h"
#include "engine/scheduler.h"
#include "systems/physics_pipeline.h"

namespace ballpit::profiling {

namespace {

// Threads used to prepare worlds; the result is the same for any count (determinism).
constexpr int kPrepareThreads = 2;

struct Cache {
  PreparedKind kind = PreparedKind::Packed;
  std::size_t n = 0;
  std::unique_ptr<World> world;
};

}  // namespace

std::string_view kind_name(PreparedKind kind) { return kind == PreparedKind::Packed ? "packed" : "settled"; }

std::size_t settled_max_spheres() {
  const char* s = std::getenv("BALLPIT_BENCH_SETTLED_MAX");
  return s ? static_cast<std::size_t>(std::strtoull(s, nullptr, 10)) : 10000;
}

World make_packed_world(std::size_t n) {
  World world;
  // PourScene::build with no spheres sets the pit, materials, gravity and step exactly as the
  // pour does; the pit width then follows the real N.
  PourScene scene;
  scene.spheres = 0;
  scene.build(world);
  scene.spheres = n;
  const float half = 0.5f * scene.pit_width();
  world.pit.half_width = half;

  const float r = scene.radius;
  const float spacing = 2.0f * r;  // touching: a resting lattice
  const float gap = 1e-3f;         // clearance from the walls (unit: m)
  const int per_row = std::max(1, static_cast<int>(std::floor((2.0f * (half - gap)) / spacing)));
  const float first = -0.5f * spacing * static_cast<float>(per_row - 1);
  world.spheres.reserve(n);
  world.entities.reserve(n);
  std::size_t added = 0;
  for (int layer = 0; added < n; ++layer) {
    for (int iz = 0; iz < per_row && added < n; ++iz) {
      for (int ix = 0; ix < per_row && added < n; ++ix) {
        SphereDesc d;
        d.position = Vec3(first + spacing * static_cast<float>(ix), r + spacing * static_cast<float>(layer),
                          first + spacing * static_cast<float>(iz));
        d.radius = r;
        d.mass = scene.mass;
        d.color = ball_color(added);
        world.add_sphere(d);
        ++added;
      }
    }
  }
  return world;
}

void step_world(World& world, int steps, int threads) {
  omp_set_num_threads(threads);
  Scheduler scheduler(threads);
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);
  for (int s = 0; s < steps; ++s) loop.step();
}

const World& prepared_world(PreparedKind kind, std::size_t n) {
  static Cache cache;
  if (cache.world && cache.kind == kind && cache.n == n) return *cache.world;
  cache.world.reset();  // free the previous size before making the next
  auto world = std::make_unique<World>();
  if (kind == PreparedKind::Packed) {
    *world = make_packed_world(n);
    step_world(*world, kPackedWarmSteps, kPrepareThreads);
  } else {
    PourScene scene;
    scene.spheres = n;
    scene.build(*world);
    step_world(*world, kSettleSteps, kPrepareThreads);
  }
  cache = {kind, n, std::move(world)};
  return *cache.world;
}

}  // namespace ballpit::profiling
