#include "app/instance_stream.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "engine/error.h"

namespace ballpit {

namespace {

void wait_for(GLsync fence) {
  if (!fence) return;
  // Flush on the first wait so the fence is sure to be submitted; a second or later wait
  // means the GPU is more than two frames behind.
  GLenum r = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1'000'000'000);
  while (r == GL_TIMEOUT_EXPIRED) r = glClientWaitSync(fence, 0, 1'000'000'000);
  if (r == GL_WAIT_FAILED) throw Error("OpenGL: waiting on an instance buffer fence failed");
}

}  // namespace

InstanceStream::~InstanceStream() { release_fences(); }

void InstanceStream::release_fences() {
  for (GLsync& f : fences_) {
    if (f) glDeleteSync(f);
    f = nullptr;
  }
}

void InstanceStream::reserve(std::size_t bytes) {
  if (bytes <= region_bytes_) return;
  for (GLsync f : fences_) wait_for(f);
  release_fences();
  // 256 is the largest storage-buffer offset alignment drivers ask for.
  region_bytes_ = (std::max<std::size_t>(bytes, 4096) + 255) & ~std::size_t{255};
  buffer_ = GlBuffer();
  const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  const auto total = static_cast<GLsizeiptr>(region_bytes_ * kRegions);
  glNamedBufferStorage(buffer_.id(), total, nullptr, flags);
  mapped_ = static_cast<std::byte*>(glMapNamedBufferRange(buffer_.id(), 0, total, flags));
  if (!mapped_) {
    region_bytes_ = 0;
    throw Error("OpenGL: cannot map a " + std::to_string(total >> 20) + " MB instance buffer persistently");
  }
  current_ = kRegions - 1;
}

std::byte* InstanceStream::acquire() {
  current_ = (current_ + 1) % kRegions;
  GLsync& f = fences_[static_cast<std::size_t>(current_)];
  wait_for(f);
  if (f) glDeleteSync(f);
  f = nullptr;
  return mapped_ + static_cast<std::size_t>(offset());
}

void InstanceStream::retire() {
  if (empty()) return;
  GLsync& f = fences_[static_cast<std::size_t>(current_)];
  if (f) glDeleteSync(f);
  f = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

void parallel_copy(void* destination, const void* source, std::size_t bytes) {
  constexpr std::size_t kChunk = std::size_t{1} << 18;
  const auto chunks = static_cast<std::int64_t>((bytes + kChunk - 1) / kChunk);
  auto* d = static_cast<std::byte*>(destination);
  const auto* s = static_cast<const std::byte*>(source);
#pragma omp parallel for schedule(static) if (chunks > 4)
  for (std::int64_t c = 0; c < chunks; ++c) {
    const std::size_t begin = static_cast<std::size_t>(c) * kChunk;
    std::memcpy(d + begin, s + begin, std::min(kChunk, bytes - begin));
  }
}

}  // namespace ballpit
