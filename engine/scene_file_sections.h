// The scene file's two largest sections as JSON: a sphere population (whose radius, colour
// scheme and placement each take one of several shapes) and the character. scene_file.cpp
// reads and writes the rest; both go through JsonFields, so errors read the same everywhere.
#pragma once

#include <string>

#include "engine/json_fields.h"
#include "engine/scene_file.h"

namespace ballpit {

Json population_to_json(const Population& p);
// `path` is the population's field path ("populations.2").
Population parse_population(const Json& j, const std::string& path, const std::string& source);

Json character_to_json(const SceneCharacter& c);
// Checks the model file exists; its clip names are checked when the scene is built.
SceneCharacter parse_character(const Json& j, const std::string& source);

}  // namespace ballpit
