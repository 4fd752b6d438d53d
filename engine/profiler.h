// Per-system timing, collected by the scheduler around every system run: per-frame totals for
// the mean / median / p95 table, and (when asked) Chrome trace events that Perfetto and
// chrome://tracing open, one track per thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace ballpit {

struct SystemStats {
  std::string name;
  double mean_ms = 0.0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double last_ms = 0.0;
  std::size_t frames = 0;
};

class Profiler {
 public:
  using Clock = std::chrono::steady_clock;

  void set_tracing(bool on) { tracing_ = on; }
  bool tracing() const { return tracing_; }

  void begin_frame();
  void end_frame();
  // Between these, the frames are the passes of one step (engine/step_passes.h), and they count
  // as one frame: the table's medians stay per step however many passes a step takes.
  void begin_step();
  void end_step();
  // Adds one timed run of `name` to the current frame; thread-safe.
  void record(const std::string& name, Clock::time_point start, Clock::time_point end);

  // Stats over every frame so far (or the last `window` frames when window > 0).
  std::vector<SystemStats> stats(std::size_t window = 0) const;
  std::string table() const;
  // Writes the Chrome trace JSON to path through a temporary file that replaces path only when
  // complete; throws ballpit::Error naming the path on failure.
  void write_trace(const std::string& path) const;
  void reset();

 private:
  struct Series {
    std::string name;
    std::vector<double> frame_ms;  // total time per frame; 0 for frames it did not run
  };
  struct TraceEvent {
    std::string name;
    std::uint32_t thread;
    double start_us;
    double duration_us;
  };
  Series& series(const std::string& name);

  mutable std::mutex mutex_;
  std::vector<Series> series_;
  std::vector<double> current_;  // per series, this frame
  std::vector<TraceEvent> trace_;
  std::size_t frames_ = 0;
  bool in_step_ = false;
  bool tracing_ = false;
  Clock::time_point epoch_ = Clock::now();
};

std::uint32_t small_thread_id();

}  // namespace ballpit
