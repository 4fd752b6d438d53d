// Clip sources: where each of a character's role clips comes from when the model file does not
// hold it as a whole clip, as users' characters come from their tools: a clip in a file of its
// own, matched to the skeleton by joint name (Mixamo: the character in one file, each clip in
// another); a time or frame range cut from one long take (older formats keep every action on
// one timeline); a clip whose root travels (root motion), made to play in place.
// Reads: the model file and the clip files (assimp, through the model probe). Writes: a new Model.
// Decisions:
// - The result is a derived Model: the skin model with the role clips appended under names of
//   their own (role_clip_name), so the animation system sees one model as before. The derived
//   model's load_name ("clip-sources:" + the sources as JSON) names it in snapshots, and
//   load_model rebuilds the same model from it on restore.
// - A joint the clip does not animate keeps its rest pose; a clip joint the skeleton lacks is
//   left out with one warning on stderr naming the file and the joints; a clip that matches no
//   joint at all is an error.
// - Root motion: the root joint's horizontal travel (model space, y up), taken as linear over
//   the clip from its first to its last key, is subtracted from its keys; its speed becomes the
//   clip's Clip::root_speed, which measure_gait takes as the gait speed (systems/locomotion.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "engine/json_fields.h"
#include "engine/model.h"

namespace ballpit {

// The clip roles a character section names: the locomotion roles (engine/character.h's
// LocomotionRole: idle, walk, run, required) then the one-shot actions (ActionRole: jump, kick,
// optional).
inline constexpr int kClipRoles = 5;
inline constexpr std::array<const char*, kClipRoles> kClipRoleNames = {"idle", "walk", "run", "jump", "kick"};
inline constexpr int kFirstActionRole = 3;  // jump; roles before it loop, the actions play once

struct ClipSource {
  enum class Unit : std::uint8_t { Seconds, Frames };
  enum class RootMotion : std::uint8_t { Auto, Keep, InPlace };

  std::string file;  // empty: the character's model file (in a scene file, relative to the scene's folder)
  std::string clip;  // a clip of the file by name; empty: the file's only clip
  std::optional<std::array<double, 2>> range;  // [start, end] of the clip, in `unit`; none: all of it
  Unit unit = Unit::Seconds;
  double fps = 0.0;  // frames per second when `unit` is frames (> 0); 0: the clip's ticks per second
  // Auto: in place for walk and run when the root travels more than kRootTravelFraction of the
  // model's height per cycle, kept otherwise. A plain clip name (the scene file's string form)
  // is Keep: the model's clip exactly as it is.
  RootMotion root_motion = RootMotion::Keep;
  std::string root_joint;  // the joint whose travel is root motion; empty: the root-most joint that moves

  // The model's clip of this name as it is (the scene file's string form).
  static ClipSource named(std::string name);
  // A clip of the model used as it is (the scene file's string form); no name: no clip (jump, kick).
  bool plain() const;
  bool none() const { return plain() && clip.empty(); }
  bool operator==(const ClipSource&) const = default;
};

using RoleClips = std::array<ClipSource, kClipRoles>;

// A root that travels less than this fraction of the bind pose's height over a cycle stands
// still (auto root motion keeps it): a real walk cycle travels a stride, about a third of the
// height or more; an in-place clip drifts by rounding and sway, under a percent.
inline constexpr float kRootTravelFraction = 0.05f;

// The scene file's form: a plain name (the string form) or {"file", "clip", "range",
// "range_unit", "fps", "root_motion", "root_joint"}; to_json writes only what is set.
Json clip_source_to_json(const ClipSource& s);
// `field` is the value's path ("character.clips.walk"); `role` its index in kClipRoleNames.
// Throws ballpit::Error "SOURCE: FIELD...: expected ..." like the rest of the scene file.
ClipSource parse_clip_source(const Json& j, int role, const std::string& field, const std::string& source);

// Whether the roles need a derived model (some role is not a plain clip name of the model).
bool needs_assembly(const RoleClips& roles);
// The name the role's clip has in the model the character plays: the plain name, or the name
// it is appended under in the derived model ("walk from walk.fbx clip mixamo.com s 0.5..1.7").
std::string role_clip_name(int role, const ClipSource& s);
// The load_name of the derived model of these sources (model: the skin model's name).
std::string clip_sources_name(const std::string& model, const RoleClips& roles);
bool is_clip_sources_name(const std::string& name);

// The skin model (`skin`, or loaded from `model`) with the role clips appended. Files named
// relative are taken from the working folder (the scene file resolves them beside itself).
// Throws ballpit::Error "character.clips.ROLE: file 'F' clip 'C': WHY" for a missing file, an
// unknown clip (naming the clips it has), a clip that matches no joint, a range outside the
// take or an unknown root joint.
std::shared_ptr<const Model> assemble_model(const std::string& model, const RoleClips& roles,
                                            std::shared_ptr<const Model> skin = nullptr);
// assemble_model from a clip_sources_name (load_model's way in, for snapshots).
std::shared_ptr<const Model> load_clip_sources(const std::string& name);

}  // namespace ballpit
