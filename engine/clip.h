// An animation clip: per joint, keyframes of translation, rotation and scale, each channel with
// its own key times (seconds, converted from the file's ticks). Every joint has a track; a joint
// the file does not animate gets its rest pose as a single key.
// Decision: a looping clip never jumps at its seam. If its last key lies before the end, the
// last key blends back to the first over the remaining time; if the last key lies at the end
// (as X files key it), the first key stands in for it, since the two are one instant of the
// cycle (the Wuson's run differs by up to 6 degrees there: a 9 m/s hoof kick every loop).
#pragma once

#include <string>
#include <vector>

#include "engine/math.h"
#include "engine/skeleton.h"

namespace ballpit {

struct JointTrack {
  // times[k] strictly increase; values[k] is the key at times[k] (unit: s).
  std::vector<float> translation_times;
  std::vector<Vec3> translations;
  std::vector<float> rotation_times;
  std::vector<Quat> rotations;  // unit quaternions
  std::vector<float> scale_times;
  std::vector<Vec3> scales;
};

struct Clip {
  std::string name;
  float duration = 0.0f;          // (unit: s); 0 for a single pose
  float ticks_per_second = 0.0f;  // the file's time base, kept for reports
  bool looping = true;            // cycles wrap; a non-looping clip holds its last key
  // The ground speed of the root's travel that was taken out to make the clip play in place
  // (engine/clip_sources.h), which is then its gait speed (unit: model units/s); 0: none.
  float root_speed = 0.0f;
  std::vector<JointTrack> tracks;  // one per skeleton joint
};

// One track per joint of the skeleton, each holding the joint's rest pose as its single key:
// what a clip is before the keys a file animates are read into it.
void rest_tracks(const Skeleton& skeleton, Clip& clip);

}  // namespace ballpit
