// The batch passes compiled for the build's own target (any CPU it runs on).
#define BALLPIT_LANES_TARGET generic
#include "systems/batch_kernels_impl.h"

namespace ballpit {

const BatchKernels& generic_batch_kernels() {
  static const BatchKernels kernels = generic::make_batch_kernels("generic");
  return kernels;
}

}  // namespace ballpit
