// A scalar animation curve through (time, value) keys: cubic between keys with Catmull-Rom
// tangents (flat at the first and last key), so a channel eases in and out of every pose an
// action passes through without stopping at each. Before the first key: its value; after the
// last: the last's.
#pragma once

#include <initializer_list>
#include <utility>
#include <vector>

namespace ballpit::marine {

class KeyCurve {
 public:
  KeyCurve(std::initializer_list<std::pair<float, float>> keys) : keys_(keys) {}
  float operator()(float t) const;

 private:
  std::vector<std::pair<float, float>> keys_;  // times strictly increasing (unit: s)
};

}  // namespace ballpit::marine
