#include "engine/state_hash.h"

#include <cstdio>
#include <cstring>

#include "engine/world.h"

namespace ballpit {

namespace {

// FNV-1a over 32-bit words: simple, and every bit of every float reaches the result.
struct Hasher {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void word(std::uint32_t w) {
    h ^= w;
    h *= 0x100000001b3ull;
  }
  void f(float x) {
    std::uint32_t w;
    std::memcpy(&w, &x, sizeof w);
    word(w);
  }
  void vec(const Vec3& v) {
    f(v.x());
    f(v.y());
    f(v.z());
  }
};

}  // namespace

std::uint64_t state_hash(const World& world) {
  const SphereTable& s = world.spheres;
  auto x = s.position();
  auto v = s.velocity();
  auto asleep = s.asleep();
  auto still = s.still_time();
  Hasher hash;
  hash.word(static_cast<std::uint32_t>(world.step_count));
  hash.word(static_cast<std::uint32_t>(s.size()));
  for (std::uint32_t index = 0; index < world.entities.capacity(); ++index) {
    Entity e{index, world.entities.generation_of(index)};
    if (!s.contains(e)) continue;
    std::uint32_t row = s.row(e);
    hash.word(index);
    hash.vec(x[row]);
    hash.vec(v[row]);
    if (s.has_angular()) hash.vec(s.angular_velocity()[row]);
    hash.word(asleep[row]);
    hash.f(still[row]);
  }
  // Characters: controller (input, script clock, root at both ends of the step), animation
  // clocks and blend, and the pose the colliders are moved to; then the collider rows.
  const CharacterTable& characters = world.characters;
  for (std::size_t i = 0; i < characters.size(); ++i) {
    const CharacterMotion& m = characters.motion(i);
    const CharacterPose& p = characters.pose(i);
    hash.word(characters.setup(i).entity.index);
    hash.f(m.input.forward);
    hash.f(m.input.turn);
    hash.word(m.input.run);
    hash.f(m.script_time);
    for (const RootState* r : {&m.previous, &m.current}) {
      hash.vec(r->position);
      hash.f(r->heading);
      hash.f(r->speed);
    }
    hash.f(p.phase);
    hash.f(p.idle_time);
    for (float w : p.weights) hash.f(w);
    for (const Affine3& t : p.model)
      for (int k = 0; k < 16; ++k) hash.f(t.matrix().data()[k]);
  }
  const ColliderTable& c = world.colliders;
  for (std::size_t k = 0; k < c.size(); ++k) {
    hash.vec(c.a()[k]);
    hash.vec(c.b()[k]);
    hash.vec(c.velocity_a()[k]);
    hash.vec(c.velocity_b()[k]);
  }
  return hash.h;
}

std::string hash_hex(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace ballpit
