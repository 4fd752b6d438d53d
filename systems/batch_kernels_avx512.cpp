// The batch passes compiled for avx512 (systems/CMakeLists.txt adds the flags; batch_kernels.cpp checks the CPU).
#define BALLPIT_LANES_TARGET avx512
#include "systems/batch_kernels_impl.h"

namespace ballpit {

const BatchKernels& avx512_batch_kernels() {
  static const BatchKernels kernels = avx512::make_batch_kernels("avx512");
  return kernels;
}

}  // namespace ballpit
