#include "engine/snapshot.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <span>

#include "engine/atomic_file.h"
#include "engine/error.h"
#include "engine/snapshot_io.h"
#include "engine/world.h"

namespace ballpit {

namespace {

using snapshot_io::Reader;
using snapshot_io::Writer;

constexpr char kMagic[8] = {'B', 'A', 'L', 'L', 'P', 'I', 'T', '\x1a'};
// 2: characters and joint colliders (version 1 held spheres only). 3: the solver's Solve sweeps
// per substep (a version 2 file is read with one, the only count it could have run). 4: the
// characters' actions (jump, kick: clips, input, the one playing); older files have none. 5:
// where each sphere's still time began (systems/sleeping.h); older files start it where the
// sphere is. 6: the last pass's length, and whether its step was split (engine/step_passes.h);
// older files resume as if the last step had run whole.
constexpr std::uint32_t kVersion = 6;
constexpr std::uint32_t kOldestReadable = 2;
using snapshot_io::kHeaderBytes;

// A new field in these structs must be written and read below: these asserts fail the build
// until it is (and the version is bumped).
static_assert(sizeof(Material) == 8, "Material changed: update snapshot.cpp and kVersion");
static_assert(sizeof(Pit) == 20, "Pit changed: update snapshot.cpp and kVersion");
static_assert(sizeof(SolverSettings) == 44, "SolverSettings changed: update snapshot.cpp and kVersion");

void put_material(Writer& w, const Material& m) {
  w.put(m.restitution);
  w.put(m.friction);
}

Material get_material(Reader& r, const char* field) {
  Material m;
  m.restitution = r.get<float>(field);
  m.friction = r.get<float>(field);
  return m;
}

template <class T>
void copy_span(std::vector<T>& out, std::span<const T> in) {
  out.assign(in.begin(), in.end());
}

}  // namespace

void capture_snapshot(const World& world, Snapshot& s) {
  const SphereTable& t = world.spheres;
  const std::size_t n = t.size();
  copy_span(s.entity_index, t.entity_index());
  s.entity_generation.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.entity_generation[i] = t.entity_at(static_cast<std::uint32_t>(i)).generation;
  copy_span(s.position, t.position());
  copy_span(s.velocity, t.velocity());
  s.has_angular = t.has_angular();
  if (s.has_angular) copy_span(s.angular_velocity, t.angular_velocity());
  else s.angular_velocity.clear();
  copy_span(s.radius, t.radius());
  copy_span(s.inv_mass, t.inv_mass());
  copy_span(s.material, t.material());
  copy_span(s.color, t.color());
  copy_span(s.still_time, t.still_time());
  copy_span(s.still_from, t.still_from());
  copy_span(s.asleep, t.asleep());

  const EntityRegistry& reg = world.entities;
  s.registry_generations.resize(reg.capacity());
  for (std::uint32_t i = 0; i < reg.capacity(); ++i) s.registry_generations[i] = reg.generation_of(i);
  s.registry_free = reg.free_list();

  s.materials = world.materials;
  s.pit = world.pit;
  s.solver = world.solver;
  s.gravity = world.gravity();
  s.dt = world.step();
  s.step_count = world.step_count;
  s.last_pass_length = world.passes.last_length;
  s.last_pass_split = world.passes.last_split;
  const ContactSet& c = world.contacts;
  s.warm_begin = c.warm_begin;
  s.warm = c.warm;
  s.warm_row_slept = c.row_slept;
  // The sleepers' entries change only when spheres fall asleep or wake: a settled pit's are
  // copied once, not every step (the NaN guard captures after each step).
  if (s.warm_kept.stamp != c.kept.stamp || c.kept.stamp == 0) s.warm_kept = c.kept;
  s.warm_stores = c.stores;
  capture_characters(world, s.characters, s.colliders);
}

void restore_snapshot(const Snapshot& s, World& world, const std::string& source) {
  auto fail = [&](const std::string& what) { throw Error(source + ": " + what); };
  const std::size_t n = s.entity_index.size();
  auto check_rows = [&](std::size_t size, const char* field) {
    if (size != n)
      fail(std::string(field) + " has " + std::to_string(size) + " rows, expected " + std::to_string(n));
  };
  check_rows(s.entity_generation.size(), "spheres.generation");
  check_rows(s.position.size(), "spheres.position");
  check_rows(s.velocity.size(), "spheres.velocity");
  if (s.has_angular) check_rows(s.angular_velocity.size(), "spheres.angular_velocity");
  else if (!s.angular_velocity.empty()) fail("spheres.angular_velocity is present but angular state is off");
  check_rows(s.radius.size(), "spheres.radius");
  check_rows(s.inv_mass.size(), "spheres.inv_mass");
  check_rows(s.material.size(), "spheres.material");
  check_rows(s.color.size(), "spheres.color");
  check_rows(s.still_time.size(), "spheres.still_time");
  if (!s.still_from.empty()) check_rows(s.still_from.size(), "spheres.still_from");
  check_rows(s.asleep.size(), "spheres.asleep");
  if (s.materials.empty()) fail("materials is empty, expected at least one");
  if (!s.warm_begin.empty()) {
    if (s.warm_begin.size() != n + 1)
      fail("contacts.warm_begin has " + std::to_string(s.warm_begin.size()) + " entries, expected " +
           std::to_string(n + 1));
    if (s.warm_begin.front() != 0 || s.warm_begin.back() != s.warm.size())
      fail("contacts.warm_begin does not span contacts.warm");
    for (std::size_t i = 0; i < n; ++i)
      if (s.warm_begin[i] > s.warm_begin[i + 1]) fail("contacts.warm_begin is not ascending at row " + std::to_string(i));
  } else if (!s.warm.empty()) {
    fail("contacts.warm has entries but contacts.warm_begin is empty");
  }

  World w;  // built aside, moved in only when complete: a bad snapshot leaves `world` as it was
  try {
    w.materials = s.materials;
    w.pit = s.pit;
    w.solver = s.solver;
    w.validate_settings();
    w.set_gravity(s.gravity);
    w.set_step(s.dt);
    w.step_count = s.step_count;
    if (!std::isfinite(s.last_pass_length) || s.last_pass_length < 0.0f)
      fail("last_pass.length must be a finite number >= 0 s, got " + std::to_string(s.last_pass_length));
    w.passes.last_length = s.last_pass_length;
    w.passes.last_split = s.last_pass_split;
    w.entities.restore(s.registry_generations, s.registry_free);
    w.enable_angular(s.has_angular);
    w.spheres.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Entity e{s.entity_index[i], s.entity_generation[i]};
      if (!w.entities.alive(e)) fail("spheres row " + std::to_string(i) + ": " + to_string(e) + " is not alive in the registry");
      if (s.material[i] >= s.materials.size())
        fail("spheres row " + std::to_string(i) + ": material " + std::to_string(s.material[i]) + " does not exist");
      if (!(s.inv_mass[i] > 0.0f) || !std::isfinite(s.inv_mass[i]))
        fail("spheres row " + std::to_string(i) + ": inv_mass must be a finite number > 0 1/kg");
      if (!std::isfinite(s.still_time[i]) || s.asleep[i] > 1 || (!s.still_from.empty() && !all_finite(s.still_from[i])))
        fail("spheres row " + std::to_string(i) + ": sleep state is invalid");
      SphereDesc d;
      d.position = s.position[i];
      d.velocity = s.velocity[i];
      d.radius = s.radius[i];
      d.mass = 1.0f / s.inv_mass[i];  // validated here; the exact inverse is restored below
      d.material = s.material[i];
      d.color = s.color[i];
      w.spheres.add(e, d);
    }
    std::copy(s.inv_mass.begin(), s.inv_mass.end(), w.spheres.mut_inv_mass().begin());
    std::copy(s.still_time.begin(), s.still_time.end(), w.spheres.mut_still_time().begin());
    std::copy(s.still_from.begin(), s.still_from.end(), w.spheres.mut_still_from().begin());
    std::copy(s.asleep.begin(), s.asleep.end(), w.spheres.mut_asleep().begin());
    if (s.has_angular) {
      for (const Vec3& a : s.angular_velocity)
        if (!all_finite(a)) fail("spheres.angular_velocity holds a non-finite value");
      std::copy(s.angular_velocity.begin(), s.angular_velocity.end(), w.spheres.mut_angular_velocity().begin());
    }
    w.contacts.set_rows_cache(s.warm_begin, s.warm);
    w.contacts.row_slept = s.warm_row_slept;
    w.contacts.kept = s.warm_kept;
    w.contacts.stores = s.warm_stores;
    restore_characters(s.characters, s.colliders, w);
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind(source, 0) == 0) throw;
    fail(what);
  }
  world = std::move(w);
}

std::string encode_snapshot(const Snapshot& s) {
  Writer w;  // the header is filled in last, once the payload's size and checksum are known
  w.out.reserve(kHeaderBytes + 64 * s.entity_index.size() + 20 * s.warm.size() + 4096);
  w.out.resize(kHeaderBytes);
  w.array(s.entity_index);
  w.array(s.entity_generation);
  w.array(s.position);
  w.array(s.velocity);
  w.put(static_cast<std::uint8_t>(s.has_angular));
  w.array(s.angular_velocity);
  w.array(s.radius);
  w.array(s.inv_mass);
  w.array(s.material);
  w.array(s.color);
  w.array(s.still_time);
  w.array(s.still_from);
  w.array(s.asleep);
  w.array(s.registry_generations);
  w.array(s.registry_free);
  w.put(static_cast<std::uint64_t>(s.materials.size()));
  for (const Material& m : s.materials) put_material(w, m);
  w.put(s.pit.half_width);
  w.put(s.pit.wall_height);
  w.put(static_cast<std::uint8_t>(s.pit.closed));
  put_material(w, s.pit.material);
  const SolverSettings& v = s.solver;
  w.put(static_cast<std::int32_t>(v.substeps));
  w.put(static_cast<std::int32_t>(v.solve_sweeps));
  w.put(v.push_out_rate);
  w.put(v.push_out_speed);
  w.put(v.restitution_threshold);
  w.put(v.linear_damping);
  w.put(v.angular_damping);
  w.put(static_cast<std::uint8_t>(v.narrowphase));
  w.put(static_cast<std::uint8_t>(v.sleeping));
  w.put(v.sleep_speed);
  w.put(v.sleep_time);
  w.put(v.wake_speed);
  w.put(s.gravity);
  w.put(s.dt);
  w.put(s.step_count);
  w.put(s.last_pass_length);
  w.put(static_cast<std::uint8_t>(s.last_pass_split));
  if (s.warm_kept.sleepers > 0) {  // the sleepers' live entries back into their rows
    ContactSet cache;
    cache.warm_begin = s.warm_begin;
    cache.warm = s.warm;
    cache.row_slept = s.warm_row_slept;
    cache.kept = s.warm_kept;
    std::vector<std::uint32_t> begin;
    std::vector<WarmStartEntry> entries;
    cache.rows_cache(s.entity_index, begin, entries);
    w.array(begin);
    w.array(entries);
  } else {
    w.array(s.warm_begin);
    w.array(s.warm);
  }
  put_characters(w, s.characters, s.colliders);

  const std::string_view payload = std::string_view(w.out).substr(kHeaderBytes);
  Writer header;
  header.out.append(kMagic, sizeof kMagic);
  header.put(kVersion);
  header.put(std::uint32_t{0});
  header.put(static_cast<std::uint64_t>(payload.size()));
  header.put(snapshot_io::payload_checksum(payload));
  w.out.replace(0, kHeaderBytes, header.out);
  return std::move(w.out);
}

Snapshot decode_snapshot(std::string_view bytes, const std::string& path) {
  auto fail = [&](const std::string& what) { throw Error("snapshot '" + path + "': " + what); };
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    fail("not a ballpit snapshot (the file does not start with the snapshot magic)");
  if (bytes.size() < kHeaderBytes)
    fail("truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the " + std::to_string(kHeaderBytes) +
         "-byte header");
  Reader header{bytes.substr(0, kHeaderBytes), sizeof kMagic, path};
  const auto version = header.get<std::uint32_t>("version");
  header.get<std::uint32_t>("reserved");
  const auto payload_bytes = header.get<std::uint64_t>("payload_bytes");
  const auto checksum = header.get<std::uint64_t>("checksum");
  if (version > kVersion)
    fail("format version " + std::to_string(version) + " is newer than this build reads (" + std::to_string(kVersion) +
         "); use a newer ballpit");
  if (version < kOldestReadable)
    fail("format version " + std::to_string(version) + " is older than this build reads (" + std::to_string(kOldestReadable) +
         ", which added character state); save the run again with this build");
  const std::uint64_t have = bytes.size() - kHeaderBytes;
  if (have < payload_bytes)
    fail("truncated: the header promises " + std::to_string(payload_bytes) + " payload bytes, the file holds " +
         std::to_string(have));
  if (have > payload_bytes)
    fail("has " + std::to_string(have - payload_bytes) + " unexpected bytes after the payload");
  const std::string_view payload = bytes.substr(kHeaderBytes);
  if (snapshot_io::payload_checksum(payload) != checksum) fail("corrupted: the payload checksum does not match the header");

  Snapshot s;
  Reader r{payload, 0, path};
  r.array("spheres.entity_index", s.entity_index);
  r.array("spheres.generation", s.entity_generation);
  r.array("spheres.position", s.position);
  r.array("spheres.velocity", s.velocity);
  s.has_angular = r.get<std::uint8_t>("spheres.has_angular") != 0;
  r.array("spheres.angular_velocity", s.angular_velocity);
  r.array("spheres.radius", s.radius);
  r.array("spheres.inv_mass", s.inv_mass);
  r.array("spheres.material", s.material);
  r.array("spheres.color", s.color);
  r.array("spheres.still_time", s.still_time);
  if (version >= 5) r.array("spheres.still_from", s.still_from);
  r.array("spheres.asleep", s.asleep);
  r.array("entities.generations", s.registry_generations);
  r.array("entities.free", s.registry_free);
  const auto materials = r.get<std::uint64_t>("materials.count");
  if (materials > payload.size() / sizeof(Material)) r.fail("materials.count is larger than the payload");
  for (std::uint64_t i = 0; i < materials; ++i) s.materials.push_back(get_material(r, "materials"));
  s.pit.half_width = r.get<float>("pit.half_width");
  s.pit.wall_height = r.get<float>("pit.wall_height");
  s.pit.closed = r.get<std::uint8_t>("pit.closed") != 0;
  s.pit.material = get_material(r, "pit.material");
  SolverSettings& v = s.solver;
  v.substeps = r.get<std::int32_t>("solver.substeps");
  v.solve_sweeps = version >= 3 ? r.get<std::int32_t>("solver.solve_sweeps") : 1;
  v.push_out_rate = r.get<float>("solver.push_out_rate");
  v.push_out_speed = r.get<float>("solver.push_out_speed");
  v.restitution_threshold = r.get<float>("solver.restitution_threshold");
  v.linear_damping = r.get<float>("solver.linear_damping");
  v.angular_damping = r.get<float>("solver.angular_damping");
  const auto narrowphase = r.get<std::uint8_t>("solver.narrowphase");
  if (narrowphase > static_cast<std::uint8_t>(NarrowphaseMode::Naive)) r.fail("solver.narrowphase is not a known mode");
  v.narrowphase = static_cast<NarrowphaseMode>(narrowphase);
  v.sleeping = r.get<std::uint8_t>("solver.sleeping") != 0;
  v.sleep_speed = r.get<float>("solver.sleep_speed");
  v.sleep_time = r.get<float>("solver.sleep_time");
  v.wake_speed = r.get<float>("solver.wake_speed");
  s.gravity = r.get<Vec3>("gravity");
  s.dt = r.get<float>("dt");
  s.step_count = r.get<std::uint64_t>("step_count");
  if (version >= 6) {
    s.last_pass_length = r.get<float>("last_pass.length");
    s.last_pass_split = r.get<std::uint8_t>("last_pass.split") != 0;
  }
  r.array("contacts.warm_begin", s.warm_begin);
  r.array("contacts.warm", s.warm);
  get_characters(r, version, s.characters, s.colliders);
  if (r.at != payload.size()) r.fail("the payload has " + std::to_string(payload.size() - r.at) + " unread bytes");
  return s;
}

void save_snapshot(const Snapshot& snapshot, const std::string& path) {
  write_file_atomically(path, encode_snapshot(snapshot));
}

void save_snapshot(const World& world, const std::string& path) {
  Snapshot s;
  capture_snapshot(world, s);
  save_snapshot(s, path);
}

void load_snapshot(World& world, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("snapshot '" + path + "': cannot open the file for reading");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(std::max<std::streamoff>(size, 0)), '\0');
  if (size < 0 || !in.read(bytes.data(), size)) throw Error("snapshot '" + path + "': read error");
  restore_snapshot(decode_snapshot(bytes, path), world, "snapshot '" + path + "'");
}

}  // namespace ballpit
