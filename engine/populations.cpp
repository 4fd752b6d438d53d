#include "engine/populations.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <sstream>
#include <unordered_map>

#include "engine/error.h"
#include "engine/world.h"

namespace ballpit {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Uniform in [0, 1) from mt19937's top 24 bits, as the pour draws its jitter: mt19937's output
// is specified, std::uniform_real_distribution's is not, so every standard library agrees.
float uniform01(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

float draw_radius(const RadiusSpec& r, std::mt19937& rng) {
  switch (r.kind) {
    case RadiusSpec::Kind::Uniform:
      return r.min + (r.max - r.min) * uniform01(rng);
    case RadiusSpec::Kind::Normal: {
      // Box-Muller from raw bits (std::normal_distribution differs between libraries); u1 is in
      // (0, 1] so the logarithm is finite.
      const double u1 = (static_cast<double>(rng() >> 8) + 1.0) / 16777216.0;
      const double u2 = uniform01(rng);
      const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
      return std::clamp(static_cast<float>(r.mean + r.sd * z), r.min, r.max);
    }
    case RadiusSpec::Kind::Fixed:
      break;
  }
  return r.value;
}

std::uint32_t lerp_color(std::uint32_t a, std::uint32_t b, float t) {
  std::uint32_t out = 0;
  for (int shift = 0; shift < 32; shift += 8) {
    const float ca = static_cast<float>((a >> shift) & 0xffu);
    const float cb = static_cast<float>((b >> shift) & 0xffu);
    const auto c = static_cast<std::uint32_t>(std::lround(ca + (cb - ca) * std::clamp(t, 0.0f, 1.0f)));
    out |= std::min(c, 255u) << shift;
  }
  return out;
}

std::uint16_t material_index(World& world, const Material& m) {
  for (std::size_t i = 0; i < world.materials.size(); ++i)
    if (world.materials[i].restitution == m.restitution && world.materials[i].friction == m.friction)
      return static_cast<std::uint16_t>(i);
  return world.add_material(m);
}

std::string text(float x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Where a population's lattice lies: nx x nz points a layer, ny layers (0: as many as the
// walls allow), the first point at (x0, y0, z0).
struct Lattice {
  int nx = 1, ny = 0, nz = 1;
  float x0 = 0.0f, y0 = 0.0f, z0 = 0.0f;
  float spacing = 0.0f;  // (unit: m)
  float jitter = 0.0f;   // (unit: m)
};

// Lattice points that fit in `room` metres at `spacing`: floor(room / spacing) + 1, none when
// room < 0, at most kMaxLatticePoints. Clamped in float before converting: for a tiny radius
// (1e-30 m) the quotient passes INT_MAX either way and the conversion would be undefined; a
// million points a row is more than any population fills.
constexpr int kMaxLatticePoints = 1 << 20;
int lattice_points(float room, float spacing) {
  const float n = std::floor(room / spacing);
  if (!(n >= 0.0f)) return 0;
  return n < static_cast<float>(kMaxLatticePoints) ? static_cast<int>(n) + 1 : kMaxLatticePoints;
}

// Lattice points along one box axis: the jittered sphere must stay inside [lo, hi].
int box_cells(float lo, float hi, float reach, float spacing) {
  const float room = hi - lo - 2.0f * reach;
  return room < 0.0f ? 0 : lattice_points(room, spacing);
}

Lattice lattice_of(const Population& pop, const World& world, float top) {
  const float r = pop.radius.largest();
  Lattice l;
  l.spacing = pop.placement.spacing_r * r;
  l.jitter = pop.placement.jitter_r * r;
  if (pop.placement.kind == Placement::Kind::Lattice) {
    // shared/SCENES.md's pour: rows whose jittered spheres stay inside the walls, centred,
    // layers from r + 0.01 m above whatever lies below.
    const float usable = 2.0f * (world.pit.half_width - r - l.jitter);
    const int per_row = std::max(1, lattice_points(usable, l.spacing));
    const float first = -0.5f * l.spacing * static_cast<float>(per_row - 1);
    l.nx = l.nz = per_row;
    l.x0 = l.z0 = first;
    l.y0 = top + r + 0.01f;
    return l;
  }
  const Vec3& lo = pop.placement.min;
  const Vec3& hi = pop.placement.max;
  const float reach = r + l.jitter;
  l.nx = box_cells(lo.x(), hi.x(), reach, l.spacing);
  l.ny = box_cells(lo.y(), hi.y(), reach, l.spacing);
  l.nz = box_cells(lo.z(), hi.z(), reach, l.spacing);
  l.x0 = 0.5f * (lo.x() + hi.x()) - 0.5f * l.spacing * static_cast<float>(l.nx - 1);
  l.z0 = 0.5f * (lo.z() + hi.z()) - 0.5f * l.spacing * static_cast<float>(l.nz - 1);
  l.y0 = lo.y() + reach;
  return l;
}

// The spheres already in the world, hashed by cell. A box population may reach into the
// populations placed before it (a lattice stacks above everything below, a box goes where it is
// told), so its lattice points skip any sphere they would overlap.
class PlacedSpheres {
 public:
  explicit PlacedSpheres(const World& world) : x_(world.spheres.position()), r_(world.spheres.radius()) {
    for (float r : r_) largest_ = std::max(largest_, r);
    cell_ = 2.0f * largest_;
    for (std::uint32_t i = 0; i < x_.size(); ++i) cells_[key(cell_of(x_[i]))].push_back(i);
  }

  bool overlaps(const Vec3& p, float r) const {
    if (cells_.empty()) return false;
    const Eigen::Vector3i c = cell_of(p);
    const int reach = static_cast<int>(std::ceil((r + largest_) / cell_));
    for (int dx = -reach; dx <= reach; ++dx)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dz = -reach; dz <= reach; ++dz) {
          auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (std::uint32_t i : it->second) {
            const float touch = r + r_[i];
            if ((x_[i] - p).squaredNorm() < touch * touch) return true;
          }
        }
    return false;
  }

 private:
  Eigen::Vector3i cell_of(const Vec3& p) const { return (p / cell_).array().floor().cast<int>(); }
  // 21 bits a coordinate: a pit spans far fewer cells than 2^21 in any direction.
  static std::uint64_t key(const Eigen::Vector3i& c) {
    auto bits = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffffu; };
    return bits(c.x()) | bits(c.y()) << 21 | bits(c.z()) << 42;
  }

  std::span<const Vec3> x_;
  std::span<const float> r_;
  float largest_ = 0.0f;
  float cell_ = 1.0f;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

void apply_colors(const Population& pop, std::uint64_t first_index, std::vector<SphereDesc>& batch) {
  const ColorScheme& c = pop.color;
  float lo = pop.radius.smallest(), hi = pop.radius.largest();
  if (c.kind == ColorScheme::Kind::ByHeight && !batch.empty()) {
    lo = hi = batch.front().position.y();
    for (const SphereDesc& d : batch) {
      lo = std::min(lo, d.position.y());
      hi = std::max(hi, d.position.y());
    }
  }
  for (std::size_t i = 0; i < batch.size(); ++i) {
    SphereDesc& d = batch[i];
    switch (c.kind) {
      case ColorScheme::Kind::Palette:
        d.color = palette_color(first_index + i, c.palette);
        break;
      case ColorScheme::Kind::Solid:
        d.color = c.color;
        break;
      case ColorScheme::Kind::ByRadius:
      case ColorScheme::Kind::ByHeight: {
        const float v = c.kind == ColorScheme::Kind::ByRadius ? d.radius : d.position.y();
        d.color = lerp_color(c.from, c.to, hi > lo ? (v - lo) / (hi - lo) : 0.0f);
        break;
      }
    }
  }
}

}  // namespace

ColorScheme::ColorScheme() : palette(ball_palette()) {}

float Population::mass_of(float r) const {
  if (!(density > 0.0f)) return mass;
  return static_cast<float>(static_cast<double>(density) * (4.0 / 3.0) * kPi * static_cast<double>(r) * r * r);
}

const std::vector<std::uint32_t>& ball_palette() {
  static const std::vector<std::uint32_t> palette = {
      0xff3030e0u,  // red    (RGBA8, red in the low byte)
      0xff20c8f8u,  // yellow
      0xffe07020u,  // blue
      0xff40c040u,  // green
      0xff2090f8u,  // orange
      0xffc050a0u,  // purple
  };
  return palette;
}

std::uint32_t palette_color(std::uint64_t index, std::span<const std::uint32_t> palette) {
  if (palette.empty()) return 0xffffffffu;
  std::uint64_t h = index * 0x9E3779B97F4A7C15ull;
  h ^= h >> 29;
  return palette[h % palette.size()];
}

std::size_t add_populations(World& world, std::span<const Population> populations, std::uint32_t seed,
                            const std::string& source, const KeepClear& keep_clear) {
  std::size_t total = 0;
  for (const Population& p : populations) total += p.count;
  world.spheres.reserve(world.spheres.size() + total);
  world.entities.reserve(world.entities.capacity() + total);

  float top = 0.0f;          // highest sphere top so far: the next lattice stacks above it (unit: m)
  std::uint64_t index = 0;   // colour index, counted over every population
  std::vector<SphereDesc> batch;
  for (std::size_t k = 0; k < populations.size(); ++k) {
    const Population& pop = populations[k];
    const std::string field = source + ": populations." + std::to_string(k);
    const std::uint16_t material = material_index(world, pop.material);
    // One stream per population; population 0 draws from the scene seed itself (the pour's).
    std::mt19937 rng(seed ^ (static_cast<std::uint32_t>(k) * 0x9E3779B9u));
    // Velocity jitter draws from a second stream, so a population's places are the same with
    // and without it (and with none, nothing is drawn).
    std::mt19937 velocity_rng(seed ^ (static_cast<std::uint32_t>(k) * 0x9E3779B9u) ^ 0x5BD1E995u);
    const float r_max = pop.radius.largest();
    const Lattice l = lattice_of(pop, world, top);
    std::optional<PlacedSpheres> placed;
    if (pop.placement.kind == Placement::Kind::Box && world.spheres.size() > 0) placed.emplace(world);
    std::size_t taken = 0;  // lattice points of the box that earlier spheres occupy
    batch.clear();
    batch.reserve(pop.count);
    for (int layer = 0; batch.size() < pop.count; ++layer) {
      const float y = l.y0 + l.spacing * static_cast<float>(layer);
      if (pop.placement.kind == Placement::Kind::Box && layer >= l.ny) {
        throw Error(field + ".placement: the box holds only " + std::to_string(batch.size()) + " of the " +
                    std::to_string(pop.count) + " spheres (lattice spacing " + text(l.spacing) + " m" +
                    (taken ? ", " + std::to_string(taken) + " points taken by earlier populations" : "") +
                    "); expected a larger box or a smaller count");
      }
      if (y + r_max > world.pit.wall_height) {
        throw Error(field + ".count: only " + std::to_string(batch.size()) + " of the " + std::to_string(pop.count) +
                    " spheres fit below the " + text(world.pit.wall_height) + " m walls (lattice spacing " +
                    text(l.spacing) + " m); expected fewer spheres, a wider pit or higher walls");
      }
      for (int iz = 0; iz < l.nz && batch.size() < pop.count; ++iz) {
        for (int ix = 0; ix < l.nx && batch.size() < pop.count; ++ix) {
          Vec3 p(l.x0 + l.spacing * static_cast<float>(ix), y, l.z0 + l.spacing * static_cast<float>(iz));
          for (int a = 0; a < 3; ++a) p[a] += (2.0f * uniform01(rng) - 1.0f) * l.jitter;
          const float r = draw_radius(pop.radius, rng);
          if (keep_clear && keep_clear(p, r)) continue;
          if (placed && placed->overlaps(p, r)) {
            ++taken;
            continue;
          }
          SphereDesc d;
          d.position = p;
          d.radius = r;
          d.mass = pop.mass_of(r);
          d.material = material;
          d.velocity = pop.velocity;
          if (pop.velocity_jitter > 0.0f)
            for (int a = 0; a < 3; ++a) d.velocity[a] += (2.0f * uniform01(velocity_rng) - 1.0f) * pop.velocity_jitter;
          d.angular_velocity = pop.spin;
          batch.push_back(d);
        }
      }
    }
    apply_colors(pop, index, batch);
    for (const SphereDesc& d : batch) {
      world.add_sphere(d);
      top = std::max(top, d.position.y() + d.radius);
    }
    index += batch.size();
  }
  return total;
}

}  // namespace ballpit
