#include "engine/profiler.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <sstream>

#include "engine/atomic_file.h"

namespace ballpit {

std::uint32_t small_thread_id() {
  static std::atomic<std::uint32_t> next{0};
  thread_local std::uint32_t id = next++;
  return id;
}

Profiler::Series& Profiler::series(const std::string& name) {
  for (Series& s : series_)
    if (s.name == name) return s;
  series_.push_back({name, std::vector<double>(frames_, 0.0)});
  current_.push_back(0.0);
  return series_.back();
}

void Profiler::begin_frame() {
  std::lock_guard lock(mutex_);
  if (!in_step_) std::fill(current_.begin(), current_.end(), 0.0);
}

void Profiler::end_frame() {
  std::lock_guard lock(mutex_);
  if (in_step_) return;
  for (std::size_t i = 0; i < series_.size(); ++i) series_[i].frame_ms.push_back(current_[i]);
  ++frames_;
}

void Profiler::begin_step() {
  std::lock_guard lock(mutex_);
  std::fill(current_.begin(), current_.end(), 0.0);
  in_step_ = true;
}

void Profiler::end_step() {
  {
    std::lock_guard lock(mutex_);
    in_step_ = false;
  }
  end_frame();
}

void Profiler::record(const std::string& name, Clock::time_point start, Clock::time_point end) {
  double ms = std::chrono::duration<double, std::milli>(end - start).count();
  std::lock_guard lock(mutex_);
  Series& s = series(name);
  current_[static_cast<std::size_t>(&s - series_.data())] += ms;
  if (tracing_) {
    trace_.push_back({name, small_thread_id(),
                      std::chrono::duration<double, std::micro>(start - epoch_).count(), ms * 1000.0});
  }
}

std::vector<SystemStats> Profiler::stats(std::size_t window) const {
  std::lock_guard lock(mutex_);
  std::vector<SystemStats> out;
  for (const Series& s : series_) {
    std::size_t n = s.frame_ms.size();
    std::size_t first = (window > 0 && n > window) ? n - window : 0;
    std::vector<double> v(s.frame_ms.begin() + static_cast<std::ptrdiff_t>(first), s.frame_ms.end());
    SystemStats st;
    st.name = s.name;
    st.frames = v.size();
    if (!v.empty()) {
      st.last_ms = v.back();
      double sum = 0;
      for (double x : v) sum += x;
      st.mean_ms = sum / static_cast<double>(v.size());
      std::sort(v.begin(), v.end());
      st.median_ms = v[v.size() / 2];
      st.p95_ms = v[std::min(v.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(v.size())))];
    }
    out.push_back(st);
  }
  return out;
}

std::string Profiler::table() const {
  std::ostringstream o;
  char line[160];
  std::snprintf(line, sizeof line, "%-22s %10s %10s %10s\n", "system", "mean ms", "median ms", "p95 ms");
  o << line;
  double total_mean = 0;
  for (const SystemStats& s : stats()) {
    std::snprintf(line, sizeof line, "%-22s %10.3f %10.3f %10.3f\n", s.name.c_str(), s.mean_ms, s.median_ms,
                  s.p95_ms);
    o << line;
    total_mean += s.mean_ms;
  }
  std::snprintf(line, sizeof line, "%-22s %10.3f\n", "(sum of means)", total_mean);
  o << line;
  return o.str();
}

void Profiler::write_trace(const std::string& path) const {
  std::ostringstream o;
  o << "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n";
  std::lock_guard lock(mutex_);
  bool first = true;
  for (const TraceEvent& e : trace_) {
    if (!first) o << ",\n";
    first = false;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "{\"name\":\"%s\",\"cat\":\"system\",\"ph\":\"X\",\"pid\":1,\"tid\":%u,\"ts\":%.3f,\"dur\":%.3f}",
                  e.name.c_str(), e.thread, e.start_us, e.duration_us);
    o << buf;
  }
  o << "\n]}\n";
  write_file_atomically(path, o.str());
}

void Profiler::reset() {
  std::lock_guard lock(mutex_);
  series_.clear();
  current_.clear();
  trace_.clear();
  frames_ = 0;
}

}  // namespace ballpit
