// The app's default scene: the pour scene's balls (radius, mass, materials, colours, jittered
// lattice) around the default character, in a pit wide enough for it to walk. Reads the model
// file; writes a fresh World (pit, materials, gravity, character, balls).
// Decision: the pit is sized for the character, not by the pour formula alone. The marine's
// controller keeps a 0.84 m footprint circle (his kick's reach) inside the walls and he walks
// at 1.4 m/s, so the pit leaves his root walk_room from the centre each way, two seconds of
// walking; a pour-sized pit under ~90,000 balls is widened to that and its balls spread thinner. The character stands lifted as in the canonical pit-character scene
// (systems/pit_character_scene.h); lattice points inside its colliders are skipped, so no
// ball starts inside it.
#pragma once

#include <cstddef>
#include <memory>

#include "engine/character.h"
#include "systems/character_pipeline.h"

namespace ballpit {

class World;

struct PlayScene {
  std::size_t spheres = 40000;
  CharacterDesc character;   // the built-in marine unless the caller changes it
  // Room the character's root has to walk from the centre towards each wall (unit: m).
  float walk_room = 3.0f;
  bool sleeping = true;      // settled balls sleep: an idle pit costs little

  // Half width of the pit for a character whose footprint radius is given (unit: m).
  float half_width(float footprint_radius, float wall_clearance) const;
  // Builds into an empty world; returns the character. `model` saves re-importing the file on
  // a reset; without it the file is imported (ballpit::Error naming it if that fails).
  Entity build(World& world, std::shared_ptr<const Model> model = nullptr) const;
};

// Where the character stands at the pit's centre: lifted, as in the canonical pit-character
// scene, so its lowest collider in any pose clears the floor by the lattice spacing.
RootState standing_root(const CharacterSetup& setup, float heading);

// Places `count` balls on the pour scene's jittered lattice in the pit (layers from the floor
// up, or from `floor_y` up), skipping points whose ball would touch a joint collider. Colours
// continue from `first_color_index`. Returns how many were placed (fewer if the pit's walls
// are reached).
std::size_t place_balls(World& world, std::size_t count, float floor_y, std::uint32_t seed,
                        std::uint64_t first_color_index);

}  // namespace ballpit
