// The stateless animation jobs, in the spirit of ozz-animation's sampling, blending and
// local-to-model jobs: each reads a clip or poses and writes one output, nothing else.
// Sampling lerps translations and scales and slerps rotations between the two keys around the
// time; at a key time it returns the key exactly (the interpolation parameter is then 0).
// Decision: keys are found from the cursor of the last sample, walking a few keys forward or
// back; only a jump (a seek, or a blend that skipped the clip for a while) falls back to a
// binary search. No frame scans a track from its first key.
#pragma once

#include <span>
#include <vector>

#include "engine/clip.h"
#include "engine/math.h"
#include "engine/pose.h"
#include "engine/skeleton.h"

namespace ballpit {

// A time (unit: s) mapped into the clip: a looping clip wraps into [0, duration), another
// clamps to [0, duration]. A single-pose clip (duration 0) always samples at 0.
float clip_local_time(const Clip& clip, float time);

// Samples every joint of the clip at `time` (wrapped or clamped as above) into `out`.
// `cursor` must have been reset for the clip's joint count (ClipCursor::reset).
void sample_clip(const Clip& clip, float time, ClipCursor& cursor, LocalPose& out);

// The skeleton's rest pose (the file's node transforms).
void rest_pose(const Skeleton& skeleton, LocalPose& out);

// Weighted blend: translations and scales by weighted sum, rotations by normalised weighted
// sum in one hemisphere (nlerp, as ozz blends). Weights need not be normalised but must be
// >= 0 with a positive total; poses with weight 0 are not read. One pose of non-zero weight
// is copied exactly.
void blend_poses(std::span<const LocalPose* const> poses, std::span<const float> weights, LocalPose& out);

// Model-space transform of every joint: parent's model transform times the joint's local TRS.
void local_to_model(const Skeleton& skeleton, const LocalPose& local, std::vector<Affine3>& model);

}  // namespace ballpit
