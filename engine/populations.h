// Sphere populations: how a scene describes its balls (count, radius or radius distribution,
// mass or density, material, colour scheme, placement), and the one function that turns them
// into spheres. Reads: the world's pit. Writes: spheres, and materials a population adds.
// Decision: every placement is a jittered lattice, shared/SCENES.md's pour (spacing 2.2 r,
// jitter +-0.05 r per axis from raw mt19937 bits, layer by layer from the floor), so no two
// spawned spheres overlap whatever the radius distribution, and the canonical pour is the
// one-population case bit for bit. Random draws use one stream per population, seeded from the
// scene seed, so adding a population never changes the ones before it (velocity jitter has a
// second stream of its own, so it never moves a sphere's place).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "engine/math.h"
#include "engine/settings.h"

namespace ballpit {

class World;

// A population's radius: one value, or a distribution drawn per sphere from the scene seed.
struct RadiusSpec {
  enum class Kind : std::uint8_t { Fixed, Uniform, Normal };
  Kind kind = Kind::Fixed;
  float value = 0.04f;  // Fixed (unit: m)
  float min = 0.0f;     // Uniform's bounds, Normal's clamp (unit: m)
  float max = 0.0f;     // (unit: m)
  float mean = 0.0f;    // Normal (unit: m)
  float sd = 0.0f;      // Normal's standard deviation (unit: m)

  float smallest() const { return kind == Kind::Fixed ? value : min; }
  float largest() const { return kind == Kind::Fixed ? value : max; }
};

// Colours as RGBA8 with red in the low byte (the sphere table's colour column).
struct ColorScheme {
  enum class Kind : std::uint8_t { Palette, Solid, ByRadius, ByHeight };
  Kind kind = Kind::Palette;
  std::vector<std::uint32_t> palette;    // Palette: picked by hashing the sphere's index
  std::uint32_t color = 0xffffffffu;     // Solid
  std::uint32_t from = 0xffe07020u;      // ByRadius: smallest radius; ByHeight: lowest spawn
  std::uint32_t to = 0xff3030e0u;        // ByRadius: largest radius; ByHeight: highest spawn

  ColorScheme();  // the ball-pit palette
};

struct Placement {
  // Lattice: the whole pit floor, layers stacked above everything placed before (the floor,
  // for the first population). Box: the same lattice inside [min, max].
  enum class Kind : std::uint8_t { Lattice, Box };
  Kind kind = Kind::Lattice;
  float spacing_r = 2.2f;   // lattice spacing, in largest radii: >= 2 + 2 jitter_r, so none overlap
  float jitter_r = 0.05f;   // jitter per axis, uniform in +-jitter_r largest radii
  Vec3 min = Vec3::Zero();  // Box corners (unit: m)
  Vec3 max = Vec3::Zero();
};

struct Population {
  std::size_t count = 10000;
  RadiusSpec radius;
  float mass = 0.05f;      // (unit: kg) each, unless density is set
  float density = 0.0f;    // (unit: kg/m^3) > 0: each sphere's mass is density x its volume
  Material material;
  ColorScheme color;
  Placement placement;
  // How the population starts moving: every sphere at `velocity`, plus a per-axis draw uniform
  // in +-velocity_jitter (from a stream of its own, so jitter never moves a sphere's place),
  // spinning at `spin`. A volley fired into the pit is a population with a velocity.
  Vec3 velocity = Vec3::Zero();  // (unit: m/s)
  float velocity_jitter = 0.0f;  // (unit: m/s) per axis
  Vec3 spin = Vec3::Zero();      // angular velocity (unit: rad/s); needs the angular state

  float mass_of(float radius) const;  // (unit: kg)
};

// The ball-pit colours the pour uses: red, yellow, blue, green, orange, purple.
const std::vector<std::uint32_t>& ball_palette();
// A palette colour picked by hashing `index`, so every run colours the same sphere the same way.
std::uint32_t palette_color(std::uint64_t index, std::span<const std::uint32_t> palette);

// Whether a lattice point must stay empty (a ball of this radius there would start inside
// something the caller keeps clear, such as a character's colliders).
using KeepClear = std::function<bool(const Vec3& position, float radius)>;

// Adds every population's spheres to a world whose pit is set. Materials are matched or added
// to world.materials. Throws ballpit::Error "SOURCE: populations.K...: ..." when a population
// does not fit (below the walls, or in its box). Returns the number of spheres added.
std::size_t add_populations(World& world, std::span<const Population> populations, std::uint32_t seed,
                            const std::string& source, const KeepClear& keep_clear = {});

}  // namespace ballpit
