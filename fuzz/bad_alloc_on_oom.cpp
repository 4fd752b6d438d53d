// For the model-import target only: a failed allocation throws std::bad_alloc, as it does in a
// normal build, instead of ending the process with a sanitizer report.
// Why: assimp trusts the counts in a file, so a damaged .X file that claims four billion
// vertices makes it allocate tens of gigabytes. In a normal build that allocation throws
// std::bad_alloc, assimp catches it and import_model refuses the file with ballpit::Error
// ("assimp cannot read it: std::bad_alloc"), the clean failure. AddressSanitizer's operator new
// aborts instead (it has no bad_alloc path), which would report assimp's habit as a crash every
// few hundred inputs and stop the fuzzer. So operator new goes through malloc, which ASan still
// instruments (redzones, use-after-free), and ASan is told to return null for a failed or
// oversized request (__asan_default_options below). What is lost: ASan's new/free mismatch
// check, for this target's process only.
#include <cstdlib>
#include <new>

namespace {

void* allocate(std::size_t size) {
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}

void* allocate_aligned(std::size_t size, std::align_val_t align) {
  void* p = nullptr;
  const std::size_t a = static_cast<std::size_t>(align);
  if (posix_memalign(&p, a < sizeof(void*) ? sizeof(void*) : a, size ? size : 1) != 0) throw std::bad_alloc();
  return p;
}

}  // namespace

// Null instead of a report for a failed allocation, and any single request above 64 MiB
// fails: no fuzz input (a few KiB) needs more, and assimp leaks what it allocated for a file it
// then refuses (scripts/lsan.supp), so big doomed allocations would soon exhaust the process.
extern "C" const char* __asan_default_options() {
  return "allocator_may_return_null=1:max_allocation_size_mb=64";
}

void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return std::malloc(size ? size : 1); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return std::malloc(size ? size : 1); }
void* operator new(std::size_t size, std::align_val_t align) { return allocate_aligned(size, align); }
void* operator new[](std::size_t size, std::align_val_t align) { return allocate_aligned(size, align); }
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  try {
    return allocate_aligned(size, align);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t& tag) noexcept {
  return operator new(size, align, tag);
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
