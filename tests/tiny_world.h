// Small worlds for tests: a pit, a material, and a physics pipeline to step them with. Each
// test builds exactly the world it talks about.
#pragma once

#include <memory>

#include "engine/fixed_step_loop.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/physics_pipeline.h"

namespace ballpit::test {

struct Sim {
  World world;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<FixedStepLoop> loop;

  // Builds the pipeline for the world as configured so far; call after setting it up.
  void start(int threads = 1) {
    scheduler = std::make_unique<Scheduler>(threads);
    add_physics_systems(*scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, *scheduler);
  }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) loop->step();
  }
  const Vec3& position(Entity e) const { return world.spheres.position()[world.spheres.row(e)]; }
  const Vec3& velocity(Entity e) const { return world.spheres.velocity()[world.spheres.row(e)]; }
};

// A pit with one material of the given restitution and friction, sleeping off.
inline void make_pit(World& w, float half_width, float restitution, float friction, bool closed = false,
                     float height = 20.0f) {
  w.pit.half_width = half_width;
  w.pit.wall_height = height;
  w.pit.closed = closed;
  w.pit.material = {restitution, friction};
  w.materials.assign(1, Material{restitution, friction});
  w.solver.sleeping = false;
  w.enable_angular(friction > 0.0f);
}

inline Entity add_ball(World& w, const Vec3& p, const Vec3& v = Vec3::Zero(), float r = 0.04f, float m = 0.05f) {
  SphereDesc d;
  d.position = p;
  d.velocity = v;
  d.radius = r;
  d.mass = m;
  return w.add_sphere(d);
}

}  // namespace ballpit::test
