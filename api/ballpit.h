// ballpit's public API: one class, Simulation, that builds a pit of spheres (from a scene file,
// a built-in scene, a snapshot, or in code), steps it, and reads it back: the sphere columns
// without copying, the report's error figures and state hash, per-system timings, save and load.
// docs/api.md is its guide; examples/hello_pit is a program that uses it.
// Decisions:
// - It lives in api/, not engine/: a Simulation assembles the systems (systems/), and engine/
//   may include nothing from systems/ (DESIGN.md's layout).
// - It includes only the standard library and engine/error.h. The engine's types (Eigen vectors,
//   SoA tables, the scheduler) stay behind a pointer, so a program compiles without Eigen's
//   headers and keeps compiling when the engine's internals change. The engine's own headers
//   are installed too (include/ballpit/engine, include/ballpit/systems) for programs that want
//   more, without this header's promise of stability.
// - Vectors cross the boundary as three floats (x, y, z): the columns are read as flat float
//   spans, three to a sphere, which NumPy and Eigen::Map both take as they are.
// Errors: every bad input throws ballpit::Error with the engine's message, which names the
// field, file or sphere at fault; the Simulation is then as it was before the call.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/error.h"

// The model probe this program runs (engine/model_probe.h): the installed CMake package defines
// it as the installed ballpit-model-probe (cmake/ballpitConfig.cmake.in); in the build tree the
// libraries know their own.
#ifndef BALLPIT_MODEL_PROBE
#define BALLPIT_MODEL_PROBE ""
#endif

namespace ballpit {

// The library's version, "MAJOR.MINOR.PATCH" (CMakeLists.txt's project version).
std::string version();

// A point (unit: m) or a velocity (unit: m/s).
struct Vector3 {
  float x = 0.0f, y = 0.0f, z = 0.0f;
};

// How two surfaces meet; a pair combines as Box2D does (engine/settings.h): restitution takes the
// bouncier surface, friction the geometric mean.
struct MaterialSpec {
  float restitution = 0.5f;  // 0..1 (unitless)
  float friction = 0.5f;     // Coulomb coefficient (unitless)
};

// An axis-aligned pit: floor at y = 0, walls at x, z = +-half_width up to wall_height, and a lid
// there when closed. Its material is the floor's, the walls' and the colliders', and is also
// material 0 of the spheres.
struct PitSpec {
  float half_width = 1.0f;    // (unit: m)
  float wall_height = 20.0f;  // (unit: m)
  bool closed = false;
  MaterialSpec material;
};

struct SphereSpec {
  Vector3 position;            // (unit: m)
  Vector3 velocity;            // (unit: m/s)
  float radius = 0.04f;        // (unit: m) > 0
  float mass = 0.05f;          // (unit: kg) > 0
  std::uint16_t material = 0;  // what add_material returned; 0 is the pit's
  std::uint32_t color = 0xffffffffu;  // RGBA8, red in the low byte (for whoever draws it)
};

// A kinematic collider: infinitely heavy, moved by its velocity alone (contacts push spheres,
// never it), as a character's limbs are but without a character. A sphere collider has one
// centre, a; a capsule is the segment a-b grown by the radius.
struct ColliderSpec {
  enum class Shape : std::uint8_t { Sphere, Capsule };
  Shape shape = Shape::Sphere;
  Vector3 a;              // centre, or the segment's start (unit: m)
  Vector3 b;              // the segment's end; ignored for a sphere (unit: m)
  float radius = 0.05f;   // (unit: m) > 0
  Vector3 velocity;       // of the whole collider (unit: m/s)
};

struct SimulationOptions {
  // OpenMP threads for the step's parallel loops, set on the thread that calls step(); 0 leaves
  // OpenMP's default. The state does not depend on it: any thread count gives the same bits.
  int threads = 0;
  // The ballpit-model-probe program that reads model files first (engine/model_probe.h), for
  // scenes with a character from a file. Empty: the one the libraries were built with. Setting
  // it sets it for the whole process (engine/model_probe.h's set_probe_program).
  std::string model_probe = BALLPIT_MODEL_PROBE;
};

// The figures of `ballpit run`'s report line (shared/SCENES.md), measured now.
struct Report {
  std::size_t spheres = 0;
  std::uint64_t steps = 0;           // steps taken since the world began (a snapshot carries it)
  double time_s = 0.0;               // steps x dt (unit: s)
  double dt = 0.0;                   // (unit: s)
  double max_penetration_r = 0.0;    // deepest sphere-sphere overlap / the smaller radius
  double mean_penetration_r = 0.0;   // mean over overlapping pairs
  std::size_t overlapping_pairs = 0;
  double max_wall_penetration_r = 0.0;  // deepest overlap with floor, walls or lid / radius
  std::size_t escaped = 0;              // spheres outside the pit
  double kinetic_energy_j = 0.0;        // translational + rotational (unit: J)
  double max_speed_mps = 0.0;           // (unit: m/s)
  std::array<double, 3> momentum{};     // (unit: kg m/s)
  std::uint64_t state_hash = 0;         // engine/state_hash.h: equal exactly when states are
  std::string state_hash_hex;           // as `ballpit run` prints it (16 hex digits)
};

// One system's time per step (engine/profiler.h), over the steps since the timings began.
struct SystemTiming {
  std::string name;
  double mean_ms = 0.0, median_ms = 0.0, p95_ms = 0.0;  // (unit: ms)
  std::size_t steps = 0;
};

class Simulation {
 public:
  // An empty pit, to fill in code: gravity -9.81 m/s^2 along y, dt 1/60 s, the solver's
  // defaults (engine/settings.h), sleeping off. Throws for a pit that is not finite and > 0.
  explicit Simulation(const PitSpec& pit = {}, const SimulationOptions& options = {});
  // A scene file (scenes/README.md), or a built-in scene by name ("pour", "pit-character"), with
  // `ballpit run --set` overrides ("populations.0.count=2000"). A scene with a character is
  // settled first, as `ballpit run` does: its settle steps run here, and its path starts.
  static Simulation from_scene(const std::string& scene, const std::vector<std::string>& overrides = {},
                               const SimulationOptions& options = {});
  // The state a snapshot file holds (save()).
  static Simulation from_snapshot(const std::string& path, const SimulationOptions& options = {});

  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ~Simulation();

  // --- Building in code (any time; spheres and colliders added after steps join the next) ---
  // Returns the material's index for SphereSpec::material.
  std::uint16_t add_material(const MaterialSpec& material);
  // Returns the sphere's id (see sphere_ids()).
  std::uint32_t add_sphere(const SphereSpec& sphere);
  // Returns the collider's index, 0, 1, ... in the order added.
  std::uint32_t add_collider(const ColliderSpec& collider);
  // A new velocity for a collider this API added (unit: m/s).
  void set_collider_velocity(std::uint32_t collider, const Vector3& velocity);

  void set_gravity(const Vector3& gravity);  // (unit: m/s^2); wakes every sleeper
  Vector3 gravity() const;
  void set_dt(float dt);  // the fixed step (unit: s), finite and > 0
  float dt() const;
  void set_substeps(int substeps);  // 1..64 (engine/settings.h says what they buy)
  int substeps() const;
  // Settled regions of the pit sleep and cost nothing until motion reaches them (systems/
  // sleeping.h). Changing it restarts the timings.
  void set_sleeping(bool sleeping);
  bool sleeping() const;

  // --- Running ---
  // Takes `steps` fixed steps of dt (>= 0). Kinematic colliders move by velocity x dt per step.
  void step(int steps = 1);
  std::uint64_t step_count() const;
  double time() const;  // step_count() x dt (unit: s)

  // --- Reading, without copying ---
  // The engine's columns, one row per sphere. Rows are reordered every step (by grid cell, so
  // neighbours sit together in memory): sphere_ids() says which sphere each row is. A column's
  // address is stable across steps while the sphere count does not change (the reorder moves
  // rows within each column's own buffer, engine/sphere_table.h), so a span taken once sees
  // every step's values; it is invalid after a call that changes the sphere count or replaces
  // the state (add_sphere, load) and with the Simulation.
  std::size_t sphere_count() const;
  std::span<const float> positions() const;   // x, y, z of each row (unit: m), 3 x sphere_count()
  std::span<const float> velocities() const;  // x, y, z of each row (unit: m/s)
  std::span<const float> radii() const;       // one per row (unit: m)
  std::span<const std::uint32_t> sphere_ids() const;  // the id add_sphere returned, per row
  std::size_t collider_count() const;

  // --- Writing, validated ---
  // New positions (unit: m) or velocities (unit: m/s) for every row, as the spans above lay
  // them out: x, y, z of each row in row order, 3 x sphere_count() floats. Every value must be
  // finite; the first row that is not is named (with its sphere id), and nothing changes.
  // Wakes every sleeper, since a pile moved by hand is no longer at rest.
  void set_positions(std::span<const float> xyz);
  void set_velocities(std::span<const float> xyz);

  // The error figures and state hash of `ballpit run`'s report, measured now (a search of its
  // own over every pair: O(N log N), not free; call it when a report is wanted).
  Report report() const;
  std::uint64_t state_hash() const;
  // Each system's time per step since the first step or reset_timings(), in pipeline order; and
  // as the table `ballpit run` prints.
  std::vector<SystemTiming> timings() const;
  std::string timings_table() const;
  void reset_timings();

  // --- Snapshots (engine/snapshot.h): versioned, checksummed, written atomically. A state
  // saved and loaded steps on to the same state hash as one never stopped. ---
  void save(const std::string& path) const;
  // Replaces the whole state with the file's; on error nothing changes. Restarts the timings.
  void load(const std::string& path);

 private:
  struct Impl;
  explicit Simulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ballpit
