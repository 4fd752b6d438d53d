#include "engine/clip_sources.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "engine/error.h"
#include "engine/model_import.h"

namespace ballpit {

namespace {

constexpr const char* kSourcesPrefix = "clip-sources:";

// Key times closer than this are one instant (unit: s): keys lie a frame apart (1/30 s for the
// Wuson, 1/60 s at most in common files), and times converted from ticks or frames to float
// seconds differ from the user's by rounding, about 1e-7 s over a few seconds.
constexpr double kSameTime = 1e-5;

// A joint whose translation keys stay within this fraction of the bind height of its first one
// does not move (rounding in files that key every joint on every frame).
constexpr float kStillFraction = 1e-4f;

constexpr std::initializer_list<const char*> kUnits = {"s", "frames"};
constexpr std::initializer_list<const char*> kRootMotions = {"auto", "keep", "in_place"};

std::string field_of(int role) {
  return std::string("character.clips.") + kClipRoleNames[static_cast<std::size_t>(role)];
}

std::string number(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

std::string list_of(const std::vector<std::string>& names, std::size_t most = 12) {
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < most; ++i) out += (i ? ", '" : "'") + names[i] + "'";
  if (names.size() > most) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

// --- Cutting a range out of a take -------------------------------------------------------------

Vec3 mix(const Vec3& a, const Vec3& b, float alpha) { return a + (b - a) * alpha; }
Quat mix(const Quat& a, const Quat& b, float alpha) { return alpha == 0.0f ? a : a.slerp(alpha, b); }

// The channel's value at t, interpolated as the animation system samples (lerp, slerp), held
// before the first key and after the last.
template <class V>
V value_at(const std::vector<float>& times, const std::vector<V>& values, double t) {
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const float alpha = static_cast<float>((t - times[k]) / (times[k + 1] - times[k]));
  return mix(values[k], values[k + 1], alpha);
}

// Keeps the keys in [a, b], shifted so a is 0, with a key at a interpolated where none lies
// there; a clip that plays once gets one at b too. A looping clip does not: the animation
// system closes its cycle from the last key to the first (engine/clip.h), as the whole clip
// would. A channel of one key (a constant) stays as it is.
template <class V>
void cut_channel(std::vector<float>& times, std::vector<V>& values, double a, double b, bool looping) {
  if (times.size() <= 1) {
    if (!times.empty()) times.front() = 0.0f;
    return;
  }
  std::vector<float> t_out;
  std::vector<V> v_out;
  const auto first_in = std::lower_bound(times.begin(), times.end(), static_cast<float>(a - kSameTime));
  const bool key_at_a = first_in != times.end() && std::abs(*first_in - a) <= kSameTime;
  if (!key_at_a && a > times.front()) {
    t_out.push_back(0.0f);
    v_out.push_back(value_at(times, values, a));
  }
  double last = -1.0;
  for (std::size_t k = static_cast<std::size_t>(first_in - times.begin()); k < times.size(); ++k) {
    if (times[k] > b + kSameTime) break;
    t_out.push_back(static_cast<float>(std::clamp(times[k] - a, 0.0, b - a)));
    v_out.push_back(values[k]);
    last = times[k];
  }
  if (!looping && last < b - kSameTime && b < times.back()) {
    t_out.push_back(static_cast<float>(b - a));
    v_out.push_back(value_at(times, values, b));
  }
  if (t_out.empty()) {  // every key lies outside the range: the value there, held
    t_out.push_back(0.0f);
    v_out.push_back(value_at(times, values, a));
  }
  times = std::move(t_out);
  values = std::move(v_out);
}

// --- Root motion -------------------------------------------------------------------------------

Affine3 first_key_transform(const JointTrack& t) {
  Affine3 l;
  l.fromPositionOrientationScale(t.translations.front(), t.rotations.front(), t.scales.front());
  return l;
}

// The root-most joint whose translation moves (joints are stored parents first).
int moving_root(const Model& m, const Clip& clip) {
  const float still = kStillFraction * std::max(m.bind_height(), 1e-6f);
  for (std::size_t j = 0; j < clip.tracks.size(); ++j) {
    const std::vector<Vec3>& p = clip.tracks[j].translations;
    for (const Vec3& v : p)
      if ((v - p.front()).norm() > still) return static_cast<int>(j);
  }
  return -1;
}

// Takes the root's horizontal travel out of the clip (see the header) and sets clip.root_speed;
// with only_if_travels, a root that travels less than kRootTravelFraction of the height per
// cycle is left as it is.
void make_in_place(const Model& m, Clip& clip, int root, bool only_if_travels) {
  JointTrack& t = clip.tracks[static_cast<std::size_t>(root)];
  const std::size_t n = t.translations.size();
  if (n < 2) return;
  // The parent's model transform, from its ancestors' first keys: ancestors of the root-most
  // moving joint do not move; those of a named root are taken as they start.
  Affine3 parent = Affine3::Identity();
  const std::vector<std::int32_t>& parents = m.skeleton.parents;
  std::vector<std::size_t> chain;
  for (int p = parents[static_cast<std::size_t>(root)]; p >= 0; p = parents[static_cast<std::size_t>(p)])
    chain.push_back(static_cast<std::size_t>(p));
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) parent = parent * first_key_transform(clip.tracks[*it]);
  const Mat3 linear = parent.linear();
  const float span = t.translation_times.back() - t.translation_times.front();
  if (!(span > 0.0f)) return;
  Vec3 travel = linear * (t.translations.back() - t.translations.front());
  travel.y() = 0.0f;
  const Vec3 velocity = travel / span;  // (unit: model units/s)
  if (only_if_travels && !(velocity.norm() * clip.duration > kRootTravelFraction * m.bind_height())) return;
  const Mat3 to_local = linear.inverse();
  for (std::size_t k = 0; k < n; ++k)
    t.translations[k] -= to_local * (velocity * (t.translation_times[k] - t.translation_times.front()));
  clip.root_speed = velocity.norm();
}

// --- Clips by node name, matched to the skeleton -------------------------------------------------

FileClip as_file_clip(const Clip& c, const Skeleton& sk) {
  FileClip f;
  f.name = c.name;
  f.duration = c.duration;
  f.ticks_per_second = c.ticks_per_second;
  f.nodes = sk.names;
  f.tracks = c.tracks;
  return f;
}

std::vector<FileClip> clips_of_model(const Model& m) {
  std::vector<FileClip> out;
  for (const Clip& c : m.clips) out.push_back(as_file_clip(c, m.skeleton));
  return out;
}

// The clip on the skeleton: every joint a track, the rest pose where the clip has none.
Clip match_to_skeleton(const FileClip& f, const Model& m, const std::string& at) {
  const Skeleton& sk = m.skeleton;
  Clip clip;
  clip.name = f.name;
  clip.duration = f.duration;
  clip.ticks_per_second = f.ticks_per_second;
  rest_tracks(sk, clip);
  std::vector<std::string> lacking;
  std::size_t matched = 0;
  for (std::size_t c = 0; c < f.nodes.size(); ++c) {
    const int j = sk.find(f.nodes[c]);
    if (j < 0) {
      lacking.push_back(f.nodes[c]);
      continue;
    }
    ++matched;
    const JointTrack& from = f.tracks[c];
    JointTrack& to = clip.tracks[static_cast<std::size_t>(j)];
    if (!from.translations.empty()) {
      to.translation_times = from.translation_times;
      to.translations = from.translations;
    }
    if (!from.rotations.empty()) {
      to.rotation_times = from.rotation_times;
      to.rotations = from.rotations;
    }
    if (!from.scales.empty()) {
      to.scale_times = from.scale_times;
      to.scales = from.scales;
    }
  }
  if (matched == 0)
    throw Error(at + ": none of the " + std::to_string(f.nodes.size()) + " joints it animates (" + list_of(f.nodes) +
                ") is a joint of the model's skeleton (" + list_of(sk.names) + ")");
  if (!lacking.empty())
    std::fprintf(stderr, "ballpit: warning: %s: animates joints the model's skeleton lacks, left out: %s\n", at.c_str(),
                 list_of(lacking).c_str());
  return clip;
}

// One role's clip, ready to append (named by the caller).
Clip role_clip(int role, const ClipSource& s, const std::string& model_name, const Model& skin,
               std::map<std::string, std::vector<FileClip>>& files) {
  const std::string file = s.file.empty() ? model_name : s.file;
  const std::string field = field_of(role);
  auto found = files.find(file);
  if (found == files.end()) {
    std::vector<FileClip> clips;
    if (file == model_name) {
      clips = clips_of_model(skin);
    } else if (is_builtin_model(file)) {
      clips = clips_of_model(*load_model(file));
    } else {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec)) throw Error(field + ": clip file '" + file + "' does not exist");
      try {
        clips = import_clips(file);
      } catch (const Error& e) {
        throw Error(field + ": " + e.what());
      }
    }
    found = files.emplace(file, std::move(clips)).first;
  }
  const std::vector<FileClip>& clips = found->second;
  std::vector<std::string> names;
  for (const FileClip& c : clips) names.push_back(c.name);
  const FileClip* chosen = nullptr;
  if (s.clip.empty()) {
    if (clips.size() != 1)
      throw Error(field + ": file '" + file + "' holds " + std::to_string(clips.size()) + " clips (" + list_of(names) +
                  "): name one with \"clip\"");
    chosen = &clips.front();
  } else {
    for (const FileClip& c : clips)
      if (c.name == s.clip) chosen = &c;
    if (!chosen)
      throw Error(field + ": file '" + file + "' has no clip named '" + s.clip + "' (its clips: " + list_of(names) +
                  ")");
  }
  const std::string at = field + ": file '" + file + "' clip '" + chosen->name + "'";
  Clip clip = match_to_skeleton(*chosen, skin, at);
  const bool looping = role < kFirstActionRole;
  clip.looping = looping;

  if (s.range) {
    const bool frames = s.unit == ClipSource::Unit::Frames;
    const double fps = s.fps > 0.0 ? s.fps : clip.ticks_per_second;
    if (frames && !(fps > 0.0)) throw Error(at + ": the take has no time base for frames: give \"fps\"");
    const double to_s = frames ? 1.0 / fps : 1.0;
    const double a = (*s.range)[0] * to_s, b = (*s.range)[1] * to_s;
    const std::string unit = frames ? " frames" : " s";
    const double take = frames ? clip.duration * fps : clip.duration;
    if (!(a >= -kSameTime && b <= clip.duration + kSameTime && a < b))
      throw Error(at + ": range [" + number((*s.range)[0]) + ", " + number((*s.range)[1]) + "]" + unit +
                  " lies outside the take (0 to " + number(take) + unit +
                  (frames ? " at " + number(fps) + " frames/s" : std::string()) + ")");
    for (JointTrack& t : clip.tracks) {
      cut_channel(t.translation_times, t.translations, a, b, looping);
      cut_channel(t.rotation_times, t.rotations, a, b, looping);
      cut_channel(t.scale_times, t.scales, a, b, looping);
    }
    clip.duration = static_cast<float>(std::min<double>(b, clip.duration) - std::max(a, 0.0));
  }

  const bool locomotion = role == 1 || role == 2;  // walk, run
  const bool in_place = s.root_motion == ClipSource::RootMotion::InPlace ||
                        (s.root_motion == ClipSource::RootMotion::Auto && locomotion);
  if (in_place && clip.duration > 0.0f) {
    int root = -1;
    if (!s.root_joint.empty()) {
      root = skin.skeleton.find(s.root_joint);
      if (root < 0)
        throw Error(at + ": root_joint '" + s.root_joint + "' is not a joint of the model's skeleton (" +
                    list_of(skin.skeleton.names) + ")");
    } else {
      root = moving_root(skin, clip);
    }
    if (root >= 0) make_in_place(skin, clip, root, s.root_motion == ClipSource::RootMotion::Auto);
  }
  return clip;
}

}  // namespace

ClipSource ClipSource::named(std::string name) {
  ClipSource s;
  s.clip = std::move(name);
  return s;
}

bool ClipSource::plain() const {
  return file.empty() && !range && unit == Unit::Seconds && fps == 0.0 && root_motion == RootMotion::Keep &&
         root_joint.empty();
}

Json clip_source_to_json(const ClipSource& s) {
  if (s.plain()) return s.clip;
  Json j = Json::object();
  if (!s.file.empty()) j["file"] = s.file;
  if (!s.clip.empty()) j["clip"] = s.clip;
  if (s.range) j["range"] = {(*s.range)[0], (*s.range)[1]};
  j["range_unit"] = kUnits.begin()[static_cast<int>(s.unit)];
  if (s.fps > 0.0) j["fps"] = s.fps;
  j["root_motion"] = kRootMotions.begin()[static_cast<int>(s.root_motion)];
  if (!s.root_joint.empty()) j["root_joint"] = s.root_joint;
  return j;
}

ClipSource parse_clip_source(const Json& j, int role, const std::string& field, const std::string& source) {
  ClipSource s;
  const bool optional = role >= kFirstActionRole;
  if (j.is_string()) {
    s.clip = j.get<std::string>();
    if (s.clip.empty() && !optional)
      scene_error(source, field, "expected a clip name or {\"file\", \"clip\", \"range\", ...}, got an empty string");
    return s;
  }
  if (!j.is_object())
    scene_error(source, field,
                "expected a clip name or {\"file\", \"clip\", \"range\", \"range_unit\", \"fps\", \"root_motion\", "
                "\"root_joint\"}, got " + json_type_name(j));
  JsonFields f(j, field, source, {"file", "clip", "range", "range_unit", "fps", "root_motion", "root_joint"});
  s.root_motion = ClipSource::RootMotion::Auto;
  f.text("file", s.file);
  std::error_code ec;
  if (!s.file.empty() && !is_builtin_model(s.file) && !std::filesystem::is_regular_file(s.file, ec))
    f.fail(f.field("file"), "expected an existing clip file, '" + s.file + "' does not exist");
  f.text("clip", s.clip);
  if (const Json* r = f.find("range")) {
    if (!r->is_array() || r->size() != 2)
      f.fail(f.field("range"), "expected [start, end] (s or frames), got " + json_type_name(*r));
    const float start = f.number_value(f.field("range") + ".0", (*r)[0], 0.0f, kNoLimit, false, "s or frames");
    const float end = f.number_value(f.field("range") + ".1", (*r)[1], 0.0f, kNoLimit, false, "s or frames");
    if (!(end > start)) f.fail(f.field("range"), "expected an end after the start, got " + r->dump());
    s.range = std::array<double, 2>{(*r)[0].get<double>(), (*r)[1].get<double>()};
  }
  int unit = 0;
  f.choice("range_unit", unit, kUnits);
  s.unit = static_cast<ClipSource::Unit>(unit);
  if (const Json* fps = f.find("fps")) s.fps = f.number_value(f.field("fps"), *fps, 0.0f, kNoLimit, true, "frames/s");
  int motion = 0;
  f.choice("root_motion", motion, kRootMotions);
  s.root_motion = static_cast<ClipSource::RootMotion>(motion);
  f.text("root_joint", s.root_joint);
  return s;
}

bool needs_assembly(const RoleClips& roles) {
  return std::any_of(roles.begin(), roles.end(), [](const ClipSource& s) { return !s.plain(); });
}

std::string role_clip_name(int role, const ClipSource& s) {
  if (s.plain()) return s.clip;
  std::string name = std::string(kClipRoleNames[static_cast<std::size_t>(role)]) + " from ";
  name += s.file.empty() ? std::string("the model") : std::filesystem::path(s.file).filename().string();
  name += s.clip.empty() ? std::string(" (its only clip)") : " clip " + s.clip;
  if (s.range)
    name += std::string(s.unit == ClipSource::Unit::Frames ? " frames " : " s ") + number((*s.range)[0]) + ".." +
            number((*s.range)[1]);
  return name;
}

std::string clip_sources_name(const std::string& model, const RoleClips& roles) {
  Json j = Json::object();
  j["model"] = model;
  Json clips = Json::object();
  for (int role = 0; role < kClipRoles; ++role)
    clips[kClipRoleNames[static_cast<std::size_t>(role)]] = clip_source_to_json(roles[static_cast<std::size_t>(role)]);
  j["clips"] = clips;
  return kSourcesPrefix + j.dump();
}

bool is_clip_sources_name(const std::string& name) { return name.rfind(kSourcesPrefix, 0) == 0; }

std::shared_ptr<const Model> assemble_model(const std::string& model_name, const RoleClips& roles,
                                            std::shared_ptr<const Model> skin) {
  if (!skin) {
    try {
      skin = is_builtin_model(model_name) ? load_model(model_name)
                                          : import_model(model_name, ModelImportOptions{.require_clips = false});
    } catch (const Error& e) {
      throw Error(std::string("character.model: ") + e.what());
    }
  }
  auto out = std::make_shared<Model>(*skin);
  out->load_name = clip_sources_name(model_name, roles);
  std::map<std::string, std::vector<FileClip>> files;
  for (int role = 0; role < kClipRoles; ++role) {
    const ClipSource& s = roles[static_cast<std::size_t>(role)];
    if (s.plain()) continue;  // a clip of the model as it is (checked by name when the character spawns)
    Clip clip = role_clip(role, s, model_name, *skin, files);
    clip.name = role_clip_name(role, s);
    for (const Clip& c : out->clips)
      if (c.name == clip.name)
        throw Error(field_of(role) + ": the model already has a clip named '" + clip.name + "'");
    out->clips.push_back(std::move(clip));
  }
  return out;
}

std::shared_ptr<const Model> load_clip_sources(const std::string& name) {
  if (!is_clip_sources_name(name)) throw Error("'" + name + "' does not name clip sources");
  Json j;
  try {
    j = Json::parse(name.substr(std::string(kSourcesPrefix).size()));
  } catch (const Json::exception& e) {
    throw Error("clip sources: not valid JSON (" + std::string(e.what()) + ")");
  }
  const std::string source = "clip sources";
  JsonFields f(j, "", source, {"model", "clips"});
  std::string model;
  f.text("model", model);
  RoleClips roles;
  if (const Json* clips = f.find("clips")) {
    JsonFields cf(*clips, "clips", source, {"idle", "walk", "run", "jump", "kick"});
    for (int role = 0; role < kClipRoles; ++role)
      if (const Json* v = cf.find(kClipRoleNames[static_cast<std::size_t>(role)]))
        roles[static_cast<std::size_t>(role)] = parse_clip_source(*v, role, field_of(role), source);
  }
  return assemble_model(model, roles);
}

}  // namespace ballpit
