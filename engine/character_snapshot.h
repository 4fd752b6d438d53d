// Characters and joint colliders in snapshots (engine/snapshot.h): captured whole, written
// field by field, and restored only after they are checked against the model file.
// Decision: what add_character derived at spawn (gaits, scale, pivot, fitted collider shapes,
// footprint) is stored, not measured again, so a restore needs only the model file and the
// engine, and no change to the systems that measure them can make a resumed run differ from
// the run that saved it. The model itself is not stored: the file is named, and its clips are
// checked by name on restore.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/character.h"
#include "engine/math.h"

namespace ballpit {

class World;
namespace snapshot_io {
struct Writer;
struct Reader;
}  // namespace snapshot_io

struct CharacterSnapshot {
  std::string model_path;
  std::array<std::string, kRoles> clip_names;  // the clips setup.clips index, by name
  CharacterSetup setup;  // setup.model is held in memory only: decoding leaves it empty, restoring imports model_path
  CharacterMotion motion;  // input, script and its clock, root at both ends of the step
  CharacterPose pose;      // phase, idle clock, blend weights, key cursors, joint transforms, palettes, foot slip
                           // (not `samples`: per-step scratch)
};

// The joint-collider table's rows, column by column.
struct ColliderSnapshot {
  std::vector<std::uint8_t> shape;  // ColliderShape
  std::vector<Vec3> a, b;           // (unit: m)
  std::vector<float> radius;        // (unit: m)
  std::vector<Vec3> velocity_a, velocity_b;  // (unit: m/s)
  std::vector<std::uint32_t> owner_index, owner_generation;
  std::vector<std::uint16_t> bone;
};

void capture_characters(const World& world, std::vector<CharacterSnapshot>& characters, ColliderSnapshot& colliders);
void put_characters(snapshot_io::Writer& w, const std::vector<CharacterSnapshot>& characters,
                    const ColliderSnapshot& colliders);
// `version`: the file's format (snapshot.cpp), for the fields later formats added.
void get_characters(snapshot_io::Reader& r, std::uint32_t version, std::vector<CharacterSnapshot>& characters,
                    ColliderSnapshot& colliders);
// Adds the collider rows and characters to `world`, whose entity registry and spheres are
// already restored. Throws ballpit::Error naming the character or collider row at fault.
void restore_characters(const std::vector<CharacterSnapshot>& characters, const ColliderSnapshot& colliders,
                        World& world);

}  // namespace ballpit
