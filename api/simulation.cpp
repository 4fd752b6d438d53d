// The public API over the engine: a World, and the scheduler and fixed-step loop that step it,
// assembled as the headless runner assembles them (app/headless_run.cpp), so a scene stepped
// here reaches the state hash `ballpit run` prints for it.
// Decision: the pipeline is built at the first step, not with the world, and again after a change
// that alters which systems a world needs (sleeping, a loaded snapshot): the systems follow
// the world as it is when it runs ("model only what a scene needs").
#include "api/ballpit.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "engine/fixed_step_loop.h"
#include "engine/memory_budget.h"
#include "engine/metrics.h"
#include "engine/model_probe.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/snapshot.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/physics_pipeline.h"
#include "systems/scene_setup.h"

namespace ballpit {

namespace {

// The columns cross the API as flat floats: a Vec3 is three packed floats (engine/math.h).
static_assert(sizeof(Vec3) == 3 * sizeof(float), "Vec3 columns are read as three floats a row");

std::span<const float> flat(std::span<const Vec3> column) {
  return {column.empty() ? nullptr : column.data()->data(), 3 * column.size()};
}

Vec3 to_vec(const Vector3& v) { return Vec3(v.x, v.y, v.z); }
Vector3 to_vector(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

Material to_material(const MaterialSpec& m, const std::string& what) {
  if (!(m.restitution >= 0.0f && m.restitution <= 1.0f))
    throw Error(what + ".restitution must be in [0, 1], got " + std::to_string(m.restitution));
  if (!(m.friction >= 0.0f && std::isfinite(m.friction)))
    throw Error(what + ".friction must be a finite number >= 0, got " + std::to_string(m.friction));
  return Material{m.restitution, m.friction};
}

}  // namespace

std::string version() { return BALLPIT_VERSION; }

struct Simulation::Impl {
  explicit Impl(const SimulationOptions& o) : options(o) {
    if (options.threads < 0) throw Error("threads must be >= 0 (0: OpenMP's default), got " + std::to_string(options.threads));
    if (!options.model_probe.empty()) set_probe_program(options.model_probe);
  }

  SimulationOptions options;
  World world;
  // Built in code: spin state is the world's to decide at the first step, from its materials.
  // A scene or snapshot decided it already.
  bool built_in_code = false;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<FixedStepLoop> loop;  // after the scheduler: destroyed first

  void use_threads() const {
    if (options.threads > 0) omp_set_num_threads(options.threads);
  }

  void drop_pipeline() {
    loop.reset();
    scheduler.reset();
  }

  // The systems this world needs, as the headless runner adds them: character systems (none
  // without a character), then the physics.
  void ensure_pipeline() {
    if (scheduler) return;
    if (built_in_code && !world.spheres.has_angular()) {
      bool friction = world.pit.material.friction > 0.0f;
      for (const Material& m : world.materials) friction = friction || m.friction > 0.0f;
      world.enable_angular(friction);  // friction spins balls; without it nothing can
    }
    world.validate_settings();
    // Two systems may run at once: the character's beside the pit's (engine/scheduler.h).
    scheduler = std::make_unique<Scheduler>(options.threads > 0 ? options.threads : 2);
    add_character_systems(*scheduler, world);
    add_physics_systems(*scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, *scheduler);
  }

  // A kinematic collider's row holds its pose at the step's start and the velocity that carries
  // it through the step (systems/joint_colliders.h); after the step it is where that velocity
  // took it. Rows a character owns are its systems' to move.
  void move_kinematic_colliders() {
    ColliderTable& c = world.colliders;
    const float dt = world.step();
    for (std::uint32_t k = 0; k < c.size(); ++k) {
      if (c.owner()[k].valid()) continue;
      const Vec3 va = c.velocity_a()[k], vb = c.velocity_b()[k];
      c.set_pose(k, c.a()[k] + dt * va, c.b()[k] + dt * vb, va, vb);
    }
  }
};

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Simulation::Simulation(const PitSpec& pit, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(options)) {
  World& w = impl_->world;
  const Material material = to_material(pit.material, "pit.material");
  w.pit.half_width = pit.half_width;
  w.pit.wall_height = pit.wall_height;
  w.pit.closed = pit.closed;
  w.pit.material = material;
  w.materials.assign(1, material);
  w.solver.sleeping = false;
  w.validate_settings();
  impl_->built_in_code = true;
}

Simulation Simulation::from_scene(const std::string& scene, const std::vector<std::string>& overrides,
                                  const SimulationOptions& options) {
  auto impl = std::make_unique<Impl>(options);
  const SceneFile file = load_scene(scene, overrides);
  refuse_if_too_big(file.total_spheres(), "populations");
  const SceneSetup setup = setup_scene(file, impl->world);
  if (setup.character.valid()) {
    // As `ballpit run`: the balls settle around the standing character, then its path starts,
    // and the timings cover the path only.
    impl->use_threads();
    impl->ensure_pipeline();
    settle_scene(setup, impl->world, *impl->scheduler);
    start_scene_path(setup, impl->world);
    impl->scheduler->profiler().reset();
  }
  return Simulation(std::move(impl));
}

Simulation Simulation::from_snapshot(const std::string& path, const SimulationOptions& options) {
  auto impl = std::make_unique<Impl>(options);
  load_snapshot(impl->world, path);
  return Simulation(std::move(impl));
}

Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

std::uint16_t Simulation::add_material(const MaterialSpec& material) {
  World& w = impl_->world;
  const Material m = to_material(material, "materials[" + std::to_string(w.materials.size()) + "]");
  if (w.materials.size() > 0xffff) throw Error("add_material: a world holds at most 65536 materials");
  w.materials.push_back(m);
  return static_cast<std::uint16_t>(w.materials.size() - 1);
}

std::uint32_t Simulation::add_sphere(const SphereSpec& sphere) {
  SphereDesc d;
  d.position = to_vec(sphere.position);
  d.velocity = to_vec(sphere.velocity);
  d.radius = sphere.radius;
  d.mass = sphere.mass;
  d.material = sphere.material;
  d.color = sphere.color;
  return impl_->world.add_sphere(d).index;  // validates, naming the sphere and the field
}

std::uint32_t Simulation::add_collider(const ColliderSpec& collider) {
  ColliderDesc d;
  d.shape = collider.shape == ColliderSpec::Shape::Capsule ? ColliderShape::Capsule : ColliderShape::Sphere;
  d.a = to_vec(collider.a);
  d.b = collider.shape == ColliderSpec::Shape::Capsule ? to_vec(collider.b) : d.a;
  d.radius = collider.radius;
  d.velocity_a = d.velocity_b = to_vec(collider.velocity);
  return impl_->world.colliders.add(d);  // validates, naming the row; owner: none
}

void Simulation::set_collider_velocity(std::uint32_t collider, const Vector3& velocity) {
  ColliderTable& c = impl_->world.colliders;
  if (collider >= c.size())
    throw Error("collider " + std::to_string(collider) + " does not exist (the world has " + std::to_string(c.size()) + ")");
  if (c.owner()[collider].valid())
    throw Error("collider " + std::to_string(collider) + " belongs to a character, whose animation moves it");
  const Vec3 v = to_vec(velocity);
  if (!all_finite(v)) throw Error("collider " + std::to_string(collider) + ": velocity must be finite");
  c.set_pose(collider, c.a()[collider], c.b()[collider], v, v);
}

void Simulation::set_gravity(const Vector3& gravity) { impl_->world.set_gravity(to_vec(gravity)); }
Vector3 Simulation::gravity() const { return to_vector(impl_->world.gravity()); }
void Simulation::set_dt(float dt) { impl_->world.set_step(dt); }
float Simulation::dt() const { return impl_->world.step(); }
void Simulation::set_substeps(int substeps) { impl_->world.set_substeps(substeps); }
int Simulation::substeps() const { return impl_->world.solver.substeps; }

void Simulation::set_sleeping(bool sleeping) {
  if (impl_->world.solver.sleeping == sleeping) return;
  impl_->world.solver.sleeping = sleeping;
  impl_->drop_pipeline();  // the wake and sleep systems come or go
}
bool Simulation::sleeping() const { return impl_->world.solver.sleeping; }

void Simulation::step(int steps) {
  if (steps < 0) throw Error("step: steps must be >= 0, got " + std::to_string(steps));
  impl_->use_threads();
  impl_->ensure_pipeline();
  for (int s = 0; s < steps; ++s) {
    impl_->loop->step();
    impl_->move_kinematic_colliders();
  }
}

std::uint64_t Simulation::step_count() const { return impl_->world.step_count; }
double Simulation::time() const {
  return static_cast<double>(impl_->world.step_count) * static_cast<double>(impl_->world.step());
}

std::size_t Simulation::sphere_count() const { return impl_->world.spheres.size(); }
std::span<const float> Simulation::positions() const { return flat(impl_->world.spheres.position()); }
std::span<const float> Simulation::velocities() const { return flat(impl_->world.spheres.velocity()); }
std::span<const float> Simulation::radii() const { return impl_->world.spheres.radius(); }
std::span<const std::uint32_t> Simulation::sphere_ids() const { return impl_->world.spheres.entity_index(); }
std::size_t Simulation::collider_count() const { return impl_->world.colliders.size(); }

namespace {

// Checks a flat x, y, z array against the table's rows, then copies it into `column` and wakes
// every sphere (as World::set_gravity does); throws ballpit::Error naming the first bad row.
void write_rows(SphereTable& spheres, std::span<Vec3> column, std::span<const float> xyz, const std::string& call,
                const char* what) {
  const std::size_t n = spheres.size();
  if (xyz.size() != 3 * n)
    throw Error(call + ": expected x, y, z for each of the " + std::to_string(n) +
                " spheres (" + std::to_string(3 * n) + " floats), got " + std::to_string(xyz.size()));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < 3; ++k)
      if (!std::isfinite(xyz[3 * i + k]))
        throw Error(call + ": row " + std::to_string(i) + " (sphere id " +
                    std::to_string(spheres.entity_index()[i]) + "): " + what + " must be finite, got (" +
                    std::to_string(xyz[3 * i]) + ", " + std::to_string(xyz[3 * i + 1]) + ", " +
                    std::to_string(xyz[3 * i + 2]) + ")");
  for (std::size_t i = 0; i < n; ++i) column[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  auto asleep = spheres.mut_asleep();
  auto still = spheres.mut_still_time();
  std::fill(asleep.begin(), asleep.end(), std::uint8_t{0});
  std::fill(still.begin(), still.end(), 0.0f);
}

}  // namespace

void Simulation::set_positions(std::span<const float> xyz) {
  SphereTable& s = impl_->world.spheres;
  write_rows(s, s.mut_position(), xyz, "set_positions", "position");
}

void Simulation::set_velocities(std::span<const float> xyz) {
  SphereTable& s = impl_->world.spheres;
  write_rows(s, s.mut_velocity(), xyz, "set_velocities", "velocity");
}

Report Simulation::report() const {
  const World& w = impl_->world;
  const Metrics m = measure(w);
  Report r;
  r.spheres = w.spheres.size();
  r.steps = w.step_count;
  r.dt = w.step();
  r.time_s = time();
  r.max_penetration_r = m.max_penetration_r;
  r.mean_penetration_r = m.mean_penetration_r;
  r.overlapping_pairs = m.overlapping_pairs;
  r.max_wall_penetration_r = m.max_wall_penetration_r;
  r.escaped = m.escaped;
  r.kinetic_energy_j = m.kinetic_energy_j;
  r.max_speed_mps = m.max_speed_mps;
  r.momentum = {m.momentum[0], m.momentum[1], m.momentum[2]};
  r.state_hash = ::ballpit::state_hash(w);
  r.state_hash_hex = hash_hex(r.state_hash);
  return r;
}

std::uint64_t Simulation::state_hash() const { return ::ballpit::state_hash(impl_->world); }

std::vector<SystemTiming> Simulation::timings() const {
  std::vector<SystemTiming> out;
  if (!impl_->scheduler) return out;
  for (const SystemStats& s : impl_->scheduler->profiler().stats())
    out.push_back({s.name, s.mean_ms, s.median_ms, s.p95_ms, s.frames});
  return out;
}

std::string Simulation::timings_table() const {
  return impl_->scheduler ? impl_->scheduler->profiler().table() : std::string();
}

void Simulation::reset_timings() {
  if (impl_->scheduler) impl_->scheduler->profiler().reset();
}

void Simulation::save(const std::string& path) const { save_snapshot(impl_->world, path); }

void Simulation::load(const std::string& path) {
  load_snapshot(impl_->world, path);  // on error the world is untouched
  impl_->built_in_code = false;       // the snapshot says whether balls spin
  impl_->drop_pipeline();
}

}  // namespace ballpit
