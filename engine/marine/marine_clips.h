// The marine's clips, keyed at 60 Hz from joint-angle curves shaped after human gait data:
// idle (breathing and a small weight shift, a loop), walk and run (in-place cycles whose
// planted foot holds still at the clip's own gait speed), jump (crouch, take-off, flight,
// landing; not looping) and kick (the right leg swings through; not looping).
#pragma once

#include <vector>

#include "engine/clip.h"
#include "engine/skeleton.h"

namespace ballpit::marine {

std::vector<Clip> make_clips(const Skeleton& skeleton);

}  // namespace ballpit::marine
