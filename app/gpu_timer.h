// GPU time of a frame's draws from GL_TIME_ELAPSED queries, read a few frames late so the CPU
// never waits for the GPU to report: on a GPU, the render cost CPU timers miss. Under llvmpipe
// the queries count only part of the rasteriser's work, so there the app finishes each frame
// and times it on the CPU instead (gl_context.h: is_software_renderer).
#pragma once

#include <array>

#include "app/gl_objects.h"

namespace ballpit {

class GpuTimer {
 public:
  void begin();
  void end();
  // Latest finished measurement (unit: ms); negative until one is available.
  double last_ms() const { return last_ms_; }
  // Waits for every query in flight (benchmarks call it after glFinish).
  void collect_all();

 private:
  void collect(bool wait);
  static constexpr int kInFlight = 4;
  std::array<GlTimerQuery, kInFlight> queries_;
  std::array<bool, kInFlight> pending_{};
  int next_ = 0;
  bool active_ = false;
  double last_ms_ = -1.0;
};

}  // namespace ballpit
