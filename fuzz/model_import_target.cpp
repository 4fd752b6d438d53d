// Fuzz target: model import (engine/model_import.h), the input read as a DirectX .X file (the
// format of the default character) through import_model, as a scene with a character does.
// A model the import accepts is then animated: every clip sampled at a few times, posed and
// skinned, since the import's promise is that anything it returns can be animated.
// Decision: only the .X format. assimp reads dozens of formats; fuzzing them all would fuzz
// assimp itself, which is not this project's code, while the .X path is the one we ship.
#include <vector>

#include "engine/error.h"
#include "engine/model_import.h"
#include "engine/pose.h"
#include "fuzz/fuzz_target.h"
#include "systems/clip_sampling.h"
#include "systems/skinning.h"

namespace {

void animate(const ballpit::Model& model) {
  using namespace ballpit;
  LocalPose local;
  ClipCursor cursor;
  std::vector<Affine3> joints;
  std::vector<Mat4> palette;
  std::vector<Vec3> skinned;
  for (const Clip& clip : model.clips) {
    cursor.reset(model.skeleton.size());
    for (float t : {0.0f, 0.37f * clip.duration, clip.duration, 1.5f * clip.duration + 0.1f}) {
      sample_clip(clip, t, cursor, local);
      local_to_model(model.skeleton, local, joints);
      for (const SkinnedMesh& mesh : model.meshes) {
        skinning_palette(mesh, joints, Affine3::Identity(), palette);
        skin_positions(mesh, palette, skinned);
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const ballpit::fuzz::TempFile file(".x");
  file.write(ballpit::fuzz::as_text(data, size));
  try {
    animate(*ballpit::import_model(file.path()));
  } catch (const ballpit::Error&) {
    // The documented clean failure: the file and what it lacks.
  }
  return 0;
}
