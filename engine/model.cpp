#include "engine/model.h"

#include <algorithm>

#include "engine/error.h"

namespace ballpit {

std::size_t Skeleton::bone_count() const {
  return static_cast<std::size_t>(std::count(is_bone.begin(), is_bone.end(), std::uint8_t{1}));
}

int Skeleton::find(std::string_view name) const {
  for (std::size_t j = 0; j < names.size(); ++j)
    if (names[j] == name) return static_cast<int>(j);
  return -1;
}

void rest_tracks(const Skeleton& sk, Clip& clip) {
  clip.tracks.resize(sk.size());
  for (std::size_t j = 0; j < sk.size(); ++j) {
    JointTrack& t = clip.tracks[j];
    t.translation_times = {0.0f};
    t.translations = {sk.rest_translation[j]};
    t.rotation_times = {0.0f};
    t.rotations = {sk.rest_rotation[j]};
    t.scale_times = {0.0f};
    t.scales = {sk.rest_scale[j]};
  }
}

std::size_t Model::vertex_count() const {
  std::size_t n = 0;
  for (const SkinnedMesh& m : meshes) n += m.positions.size();
  return n;
}

std::size_t Model::clip_index(std::string_view name) const {
  std::string known;
  for (std::size_t i = 0; i < clips.size(); ++i) {
    if (clips[i].name == name) return i;
    known += (i ? ", '" : "'") + clips[i].name + "'";
  }
  throw Error("model file '" + path + "': has no clip named '" + std::string(name) + "' (its clips: " + known + ")");
}

}  // namespace ballpit
