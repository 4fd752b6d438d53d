#include "app/session.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "app/play_scene.h"
#include "app/step_warnings.h"
#include "engine/error.h"
#include "systems/character_pipeline.h"
#include "systems/physics_pipeline.h"
#include "systems/scene_setup.h"

namespace ballpit {

Session::Session(const SessionOptions& options) : options_(options) {
  if (options_.uses_scene_file()) {
    // --spheres sets the first population's count, as in `ballpit run`.
    std::vector<std::string> set = options_.set;
    if (options_.spheres > 0) set.push_back("populations.0.count=" + std::to_string(options_.spheres));
    scene_file_ = load_scene(options_.scene, set);
    options_.spheres = scene_file_->total_spheres();
  } else if (options_.scene != "play" && options_.scene != "pour") {
    throw Error("--scene: unknown scene '" + options_.scene + "' (known: play, pour, or a .json scene file)");
  } else if (!options_.set.empty()) {
    throw Error("--set: works with a .json scene file (--scene FILE.json)");
  }
  if (options_.spheres == 0) options_.spheres = options_.scene == "play" ? PlayScene{}.spheres : PourScene{}.spheres;
  threads_ = options_.threads > 0 ? options_.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  omp_set_num_threads(threads_);
  build();
  print_step_warnings(*world_);
}

Session::~Session() = default;

void Session::build() {
  world_ = std::make_unique<World>();
  if (scene_file_) {
    // The character (if any) starts its path, or waits for the keyboard, at once: the balls
    // settle around it in view instead of behind a loading pause.
    const SceneSetup setup = setup_scene(*scene_file_, *world_, model_);
    if (world_->characters.size() > 0) {
      model_ = world_->characters.setup(0).model;
      character_desc_ = character_desc(*scene_file_->character);
      options_.colliders = character_desc_.colliders;
      start_scene_path(setup, *world_);
    }
  } else if (options_.scene == "play") {
    PlayScene scene;
    scene.spheres = options_.spheres;
    scene.character.colliders = options_.colliders;
    character_desc_ = scene.character;
    scene.build(*world_, model_);
    model_ = world_->characters.setup(0).model;
  } else {
    PourScene scene;
    scene.spheres = options_.spheres;
    scene.build(*world_);
  }
  if (solver_overridden_) {
    world_->solver = solver_;
    const Material keep = material_;
    set_restitution(keep.restitution);
    set_friction(keep.friction);
  } else {
    material_ = world_->materials.front();
  }
  world_->validate_settings();
  rebuild_scheduler();
  update_fill_height();
  ++version_;
  show_latest_ = true;
}

void Session::rebuild_scheduler() {
  loop_.reset();
  scheduler_ = std::make_unique<Scheduler>(threads_);
  // Added first so it runs before anything that moves or reorders spheres.
  previous_ = &scheduler_->emplace<PreviousPositions>();
  // Character systems before physics, so the colliders are in place for the narrowphase.
  add_character_systems(*scheduler_, *world_);
  add_physics_systems(*scheduler_, *world_);
  loop_ = std::make_unique<FixedStepLoop>(*world_, *scheduler_);
  // At most two steps a frame: where a step costs more than a frame (a million balls, a slow
  // machine) the pit runs in slow motion instead of stalling the window for catch-up steps.
  loop_->max_catch_up = 2;
}

void Session::reset() {
  solver_ = world_->solver;  // keeps what the UI changed
  build();
}

int Session::advance(double real_seconds) {
  if (paused) return 0;
  int taken = loop_->advance(real_seconds);
  if (taken > 0) {
    ++version_;
    show_latest_ = false;
  }
  return taken;
}

void Session::single_step() {
  loop_->step();
  ++version_;
  show_latest_ = true;
}

void Session::pour(std::size_t count) {
  if (count == 0) return;
  World& w = *world_;
  const PourScene scene;  // the canonical ball
  float top = 0.0f;
  for (const Vec3& p : w.spheres.position()) top = std::max(top, p.y());
  // From two lattice layers above the highest ball, so nothing spawns inside the pile.
  const std::size_t placed = place_balls(w, count, top + 4.4f * scene.radius,
                                         static_cast<std::uint32_t>(scene.seed + ++pours_), w.spheres.size());
  if (placed < count) throw Error("the pit is full: poured " + std::to_string(placed) + " of " + std::to_string(count) + " balls");
  previous_->invalidate();
  update_fill_height();
  ++version_;
  show_latest_ = true;
}

void Session::set_restitution(float e) {
  if (!std::isfinite(e) || e < 0.0f || e > 1.0f) throw Error("restitution must be in [0, 1], got " + std::to_string(e));
  for (Material& m : world_->materials) m.restitution = e;
  world_->pit.material.restitution = e;
  material_.restitution = e;
  solver_overridden_ = true;
}

void Session::set_friction(float mu) {
  if (!std::isfinite(mu) || mu < 0.0f) throw Error("friction must be >= 0, got " + std::to_string(mu));
  for (Material& m : world_->materials) m.friction = mu;
  world_->pit.material.friction = mu;
  material_.friction = mu;
  // Friction spins spheres, so the angular column must exist once any friction does.
  if (mu > 0.0f && !world_->spheres.has_angular()) world_->enable_angular(true);
  solver_overridden_ = true;
}

void Session::set_substeps(int substeps) {
  world_->set_substeps(substeps);
  solver_ = world_->solver;
  solver_overridden_ = true;
}

void Session::set_solve_sweeps(int sweeps) {
  world_->set_solve_sweeps(sweeps);
  solver_ = world_->solver;
  solver_overridden_ = true;
}

void Session::set_narrowphase(NarrowphaseMode mode) {
  world_->solver.narrowphase = mode;
  solver_ = world_->solver;
  solver_overridden_ = true;
}

float Session::restitution() const { return material_.restitution; }
float Session::friction() const { return material_.friction; }

float Session::alpha() const {
  return (paused || show_latest_ || !previous_->valid()) ? 1.0f : loop_->alpha();
}

void Session::set_character_input(const ControllerInput& input) {
  if (has_character()) world_->characters.mut_motion(0).input = input;
}

Vec3 Session::character_position() const {
  if (!has_character()) return Vec3::Zero();
  const CharacterMotion& m = world_->characters.motion(0);
  return m.previous.position + alpha() * (m.current.position - m.previous.position);
}

void Session::set_collider_kind(ColliderKind kind) {
  options_.colliders = kind;
  if (!has_character() || world_->characters.setup(0).collider_kind == kind) return;
  World& w = *world_;
  const CharacterSetup old = w.characters.setup(0);
  const CharacterMotion motion = w.characters.motion(0);
  CharacterDesc desc = character_desc_;
  desc.colliders = kind;
  character_desc_.colliders = kind;
  if (scene_file_ && scene_file_->character) scene_file_->character->colliders = kind;  // kept by a reset
  // Respawn with the same model: the collider rows are the character's only ones.
  w.entities.destroy(old.entity);
  w.characters.clear();
  w.colliders.clear();
  const Entity e = add_character(w, old.model, desc);
  // Where it stood, lifted for the new colliders' reach below the root.
  RootState root = standing_root(w.characters.setup(0), motion.current.heading);
  root.position.x() = motion.current.position.x();
  root.position.z() = motion.current.position.z();
  place_character(w, e, root);
  w.characters.mut_motion(0).input = motion.input;
}

SphereRenderState Session::sphere_render_state() const {
  SphereRenderState s;
  const SphereTable& t = world_->spheres;
  s.position = t.position();
  s.radius = t.radius();
  s.color = t.color();
  s.entity = t.entity_index();
  s.version = version_;
  s.alpha = alpha();
  if (s.alpha < 1.0f) s.previous_by_entity = previous_->by_entity();
  return s;
}

void Session::update_fill_height() {
  // Random close packing fills about 60% of the volume.
  constexpr float kPacking = 0.6f;
  double volume = 0.0;
  for (float r : world_->spheres.radius()) volume += 4.0 / 3.0 * M_PI * r * r * r;
  const double area = 4.0 * static_cast<double>(world_->pit.half_width) * world_->pit.half_width;
  fill_height_ = static_cast<float>(volume / kPacking / area);
}

OrbitCamera default_camera(const Session& session) {
  OrbitCamera camera;
  if (session.has_character()) {
    const CharacterSetup& setup = session.world().characters.setup(0);
    camera.frame_character(session.character_position(), setup.model->bind_height() * setup.scale);
  } else {
    camera.frame_pit(session.world().pit.half_width, session.fill_height());
  }
  return camera;
}

}  // namespace ballpit
