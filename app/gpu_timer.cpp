#include "app/gpu_timer.h"

namespace ballpit {

void GpuTimer::collect(bool wait) {
  // Oldest first, so last_ms_ ends at the newest finished frame.
  for (int k = 1; k <= kInFlight; ++k) {
    const int i = (next_ + k) % kInFlight;
    if (!pending_[static_cast<std::size_t>(i)]) continue;
    const GLuint q = queries_[static_cast<std::size_t>(i)].id();
    GLint available = GL_FALSE;
    if (!wait) glGetQueryObjectiv(q, GL_QUERY_RESULT_AVAILABLE, &available);
    if (wait || available) {
      GLuint64 ns = 0;
      glGetQueryObjectui64v(q, GL_QUERY_RESULT, &ns);
      last_ms_ = static_cast<double>(ns) * 1e-6;
      pending_[static_cast<std::size_t>(i)] = false;
    }
  }
}

void GpuTimer::begin() {
  collect(false);
  // A query still in flight in this slot means the GPU is four frames behind: skip timing.
  active_ = !pending_[static_cast<std::size_t>(next_)];
  if (!active_) return;
  glBeginQuery(GL_TIME_ELAPSED, queries_[static_cast<std::size_t>(next_)].id());
  pending_[static_cast<std::size_t>(next_)] = true;
}

void GpuTimer::end() {
  if (!active_) return;
  glEndQuery(GL_TIME_ELAPSED);
  active_ = false;
  next_ = (next_ + 1) % kInFlight;
}

void GpuTimer::collect_all() { collect(true); }

}  // namespace ballpit
