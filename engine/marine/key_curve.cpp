#include "engine/marine/key_curve.h"

namespace ballpit::marine {

float KeyCurve::operator()(float t) const {
  const std::size_t n = keys_.size();
  if (n == 0) return 0.0f;
  if (t <= keys_.front().first) return keys_.front().second;
  if (t >= keys_.back().first) return keys_.back().second;
  std::size_t k = 0;
  while (keys_[k + 1].first <= t) ++k;
  auto tangent = [&](std::size_t i) {
    if (i == 0 || i + 1 == n) return 0.0f;
    return (keys_[i + 1].second - keys_[i - 1].second) / (keys_[i + 1].first - keys_[i - 1].first);
  };
  const float t0 = keys_[k].first, t1 = keys_[k + 1].first, h = t1 - t0;
  const float u = (t - t0) / h, u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * keys_[k].second + (u3 - 2 * u2 + u) * h * tangent(k) +
         (-2 * u3 + 3 * u2) * keys_[k + 1].second + (u3 - u2) * h * tangent(k + 1);
}

}  // namespace ballpit::marine
