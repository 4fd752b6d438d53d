// A persistently mapped GPU buffer for per-instance data that changes every physics step. It is
// split into three regions used round-robin: the CPU copies into one while the GPU may still be
// drawing from the other two, and a fence per region makes the CPU wait (rarely) rather than
// overwrite data a draw has not read yet.
// Decision: persistent + coherent mapping (GL 4.4 buffer storage) instead of orphaning, so a
// frame's upload is a plain memcpy into memory the driver already owns, with no allocation.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstddef>

#include "app/gl_objects.h"

namespace ballpit {

class InstanceStream {
 public:
  static constexpr int kRegions = 3;

  InstanceStream() = default;
  ~InstanceStream();
  InstanceStream(const InstanceStream&) = delete;
  InstanceStream& operator=(const InstanceStream&) = delete;

  // Makes every region at least `bytes` long; growing makes a new buffer (after the GPU is
  // done with the old one), so callers reserve with headroom.
  void reserve(std::size_t bytes);
  std::size_t region_bytes() const { return region_bytes_; }

  // Moves to the next region and returns its mapped memory, waiting for the GPU to finish the
  // draws that last read it.
  std::byte* acquire();
  // Byte offset of the current region in buffer().
  GLintptr offset() const { return static_cast<GLintptr>(current_) * static_cast<GLintptr>(region_bytes_); }
  // Fences the current region after this frame's draws from it.
  void retire();
  GLuint buffer() const { return buffer_.id(); }
  bool empty() const { return region_bytes_ == 0; }

 private:
  void release_fences();

  GlBuffer buffer_{nullptr};
  std::byte* mapped_ = nullptr;
  std::size_t region_bytes_ = 0;
  int current_ = 0;
  std::array<GLsync, kRegions> fences_{};
};

// Copies with every OpenMP thread: at a million spheres the columns are 36 MB a step, and the
// physics threads are idle while the frame is built.
void parallel_copy(void* destination, const void* source, std::size_t bytes);

}  // namespace ballpit
