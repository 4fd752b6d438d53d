#include "engine/step_passes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "engine/speculative_margin.h"
#include "engine/world.h"

namespace ballpit {

float longest_capped_pass(const World& world, float margin_fraction) {
  const auto v = world.spheres.velocity();
  const auto r = world.spheres.radius();
  const auto asleep = world.spheres.asleep();
  const std::int64_t n = static_cast<std::int64_t>(v.size());
  // Squares, so that the loop takes no root. Max and min are exact, so the reduction's order
  // (the thread count) changes nothing. A NaN speed is made infinite: the pass then is 0.
  float fastest2 = 0.0f;                                      // (speed / r)^2, unit: 1/s^2
  float smallest = std::numeric_limits<float>::infinity();   // radius (unit: m)
#pragma omp parallel for schedule(static) reduction(max : fastest2) reduction(min : smallest) if (n > 16384)
  for (std::int64_t i = 0; i < n; ++i) {
    if (asleep[i]) continue;
    const float s2 = v[i].squaredNorm() / (r[i] * r[i]);
    fastest2 = std::max(fastest2, std::isnan(s2) ? std::numeric_limits<float>::infinity() : s2);
    smallest = std::min(smallest, r[i]);
  }
  if (!(smallest < std::numeric_limits<float>::infinity())) return std::numeric_limits<float>::infinity();
  return static_cast<float>(longest_pass_within(std::sqrt(static_cast<double>(fastest2)),
                                                static_cast<double>(world.gravity().norm()) / smallest, margin_fraction));
}

double longest_pass_within(double speed_per_radius, double gravity_per_radius, float margin_fraction) {
  const double a = speed_per_radius;         // 1/s
  const double b = 0.25 * gravity_per_radius;  // 1/s^2
  const double room = static_cast<double>(margin_fraction) - kMinMarginFraction;  // radii
  if (!std::isfinite(a)) return 0.0;
  // The positive root of b h^2 + a h = room, written so that b -> 0 loses nothing.
  return 2.0 * room / (a + std::sqrt(a * a + 4.0 * b * room));  // infinite when a = b = 0
}

int passes_needed(float remaining, float longest) {
  const double passes = std::ceil(static_cast<double>(remaining) / static_cast<double>(longest));
  if (!(passes < static_cast<double>(std::numeric_limits<std::int32_t>::max())))  // NaN too
    return std::numeric_limits<std::int32_t>::max();
  return std::max(1, static_cast<int>(passes));
}

void scale_warm_start(World& world, float factor) {
  world.contacts.scale_impulses(factor);
}

std::string short_of_passes_warning(const World& world, const PassRecord& record) {
  char text[600];
  const float dt = world.step();
  const int written = std::snprintf(
      text, sizeof text,
      "step %llu needed %d passes to keep every speculative margin within %.1f r (balls faster than %.3g r per "
      "%.3g s, or gravity %.3g m/s^2 on the smallest ball), and a step takes at most %d: margins were cut to the "
      "cap, so a ball may have ended inside, or past, another ball or a collider (%llu such steps so far). A dt of "
      "%.3g s or less holds it (--set dt=...), as do slower balls or weaker gravity.",
      static_cast<unsigned long long>(world.step_count), record.needed, static_cast<double>(kSplitMarginFraction),
      static_cast<double>(kSplitMarginFraction), static_cast<double>(record.longest),
      static_cast<double>(world.gravity().norm()), kMostPassesPerStep,
      static_cast<unsigned long long>(record.steps_short),
      static_cast<double>(std::min(dt, kMostPassesPerStep * record.longest)));
  return std::string(text, static_cast<std::size_t>(std::clamp(written, 0, static_cast<int>(sizeof text) - 1)));
}

}  // namespace ballpit
