// The batch passes compiled for avx2 (systems/CMakeLists.txt adds the flags; batch_kernels.cpp checks the CPU).
#define BALLPIT_LANES_TARGET avx2
#include "systems/batch_kernels_impl.h"

namespace ballpit {

const BatchKernels& avx2_batch_kernels() {
  static const BatchKernels kernels = avx2::make_batch_kernels("avx2");
  return kernels;
}

}  // namespace ballpit
