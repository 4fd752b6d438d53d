#include "engine/speculative_margin.h"

#include <algorithm>

namespace ballpit {

float pair_margin(float speed, float dt, float gravity, float radius) {
  return speed * dt + 0.25f * gravity * dt * dt + kMinMarginFraction * radius;
}

float capped_pair_margin(float speed, float dt, float gravity, float radius) {
  // std::min keeps a NaN margin NaN (its first argument), as the uncapped one was.
  return std::min(pair_margin(speed, dt, gravity, radius), kMostMarginFraction * radius);
}

float static_margin_extra(float dt, float gravity) { return 0.75f * gravity * dt * dt; }

float speculative_margin(float speed, float dt, float gravity, float radius) {
  return pair_margin(speed, dt, gravity, radius) + static_margin_extra(dt, gravity);
}

}  // namespace ballpit
