// The marine: the project's own default character, a 1.8 m humanoid in US Marine dress, made
// in code (no file needed): skeleton (marine_skeleton.h), skinned body with its camouflage
// (marine_body.h) and clips idle, walk, run, jump and kick (marine_clips.h).
// Decision: he is a plain Model, so the engine animates, collides and draws him exactly as a
// model a user imports; `ballpit make-marine FILE.glb` writes him for other tools.
#pragma once

#include <memory>

#include "engine/model.h"

namespace ballpit::marine {

// The name a scene's character.model gives for him (engine/model_import.h's load_model).
inline constexpr const char* kModelName = "builtin:marine";

// Clip names, by role.
inline constexpr const char* kIdleClip = "idle";
inline constexpr const char* kWalkClip = "walk";
inline constexpr const char* kRunClip = "run";
inline constexpr const char* kJumpClip = "jump";
inline constexpr const char* kKickClip = "kick";

// Builds him afresh (deterministic: the same bits every call).
Model make_marine();

// The marine built once per process and shared by every character that uses him.
std::shared_ptr<const Model> marine_model();

}  // namespace ballpit::marine
