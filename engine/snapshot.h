// Snapshots: the whole simulation state as one versioned, checksummed binary file, so a run can
// stop and resume bit-identically (the resumed run reaches the same state hash): spheres and
// their sleep state, the solver's warm-start cache, the step counter, the settings, and the
// characters (pose, animation clocks, controller, locomotion blend) with their collider rows.
// Decision: sphere rows are stored in their current order with the warm-start cache keyed by
// row, so the next step's grid rebuild and warm start see exactly what they would have seen.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/character_snapshot.h"
#include "engine/contact_set.h"
#include "engine/math.h"
#include "engine/settings.h"

namespace ballpit {

class World;

// The state a snapshot holds, as plain arrays (row order for the sphere columns).
struct Snapshot {
  std::vector<std::uint32_t> entity_index, entity_generation;  // entity of each row
  std::vector<Vec3> position;          // (unit: m)
  std::vector<Vec3> velocity;          // (unit: m/s)
  std::vector<Vec3> angular_velocity;  // (unit: rad/s) empty unless the world has angular state
  bool has_angular = false;
  std::vector<float> radius;           // (unit: m)
  std::vector<float> inv_mass;         // (unit: 1/kg)
  std::vector<std::uint16_t> material;
  std::vector<std::uint32_t> color;
  std::vector<float> still_time;       // (unit: s)
  std::vector<Vec3> still_from;        // (unit: m; version 5 on: older files start it where the sphere is)
  std::vector<std::uint8_t> asleep;
  std::vector<std::uint32_t> registry_generations, registry_free;  // EntityRegistry, exactly
  std::vector<Material> materials;
  Pit pit;
  SolverSettings solver;
  Vec3 gravity = Vec3::Zero();  // (unit: m/s^2)
  float dt = 0.0f;              // (unit: s)
  std::uint64_t step_count = 0;
  float last_pass_length = 0.0f;  // PassRecord::last_length (version 6 on; older: 0, nothing scaled)
  bool last_pass_split = false;   // PassRecord::last_split (version 6 on)
  std::vector<std::uint32_t> warm_begin;  // ContactSet's warm-start cache, keyed by row
  std::vector<WarmStartEntry> warm;
  // In memory only, as the world holds them: the sleepers' entries by entity (ContactSet::kept),
  // and the rows that slept. A file holds every row's live entries in warm (encode_snapshot).
  std::vector<std::uint8_t> warm_row_slept;
  SleeperCache warm_kept;
  std::uint32_t warm_stores = 0;
  ColliderSnapshot colliders;                 // joint-collider rows (format version 2 on)
  std::vector<CharacterSnapshot> characters;  // (format version 2 on)
};

// Copies the world's state into `out`, reusing its capacity (cheap enough to do every step).
void capture_snapshot(const World& world, Snapshot& out);
// Replaces the world's state with the snapshot's after validating it; `source` names the
// snapshot in errors. On error the world is untouched.
void restore_snapshot(const Snapshot& snapshot, World& world, const std::string& source = "snapshot");

// The file format: header (magic "BALLPIT\x1a", u32 version, u32 reserved, u64 payload bytes,
// u64 FNV-1a 64 of the payload), then the payload, all little-endian.
std::string encode_snapshot(const Snapshot& snapshot);
// Throws ballpit::Error naming `path` for a foreign, older, newer, truncated or corrupted file.
Snapshot decode_snapshot(std::string_view bytes, const std::string& path);

// Written through write_file_atomically: a failed save leaves the previous file intact.
void save_snapshot(const World& world, const std::string& path);
void save_snapshot(const Snapshot& snapshot, const std::string& path);
// Replaces the world's state with the file's; on error the world is untouched.
void load_snapshot(World& world, const std::string& path);

}  // namespace ballpit
