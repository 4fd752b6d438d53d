#include "systems/batch_kernels.h"

#include <cstdlib>
#include <string>

#include "engine/error.h"

namespace ballpit {

namespace {

bool cpu_runs(std::string_view name) {
#if defined(__x86_64__) || defined(__i386__)
  if (name == "avx2") return __builtin_cpu_supports("avx2");
  if (name == "avx512") return __builtin_cpu_supports("avx512f");
#endif
  return name == "generic";
}

}  // namespace

std::vector<const BatchKernels*> available_batch_kernels() {
  std::vector<const BatchKernels*> out{&generic_batch_kernels()};
#ifdef BALLPIT_AVX2_KERNELS
  if (cpu_runs("avx2")) out.push_back(&avx2_batch_kernels());
#endif
#ifdef BALLPIT_AVX512_KERNELS
  if (cpu_runs("avx512")) out.push_back(&avx512_batch_kernels());
#endif
  return out;
}

const BatchKernels& batch_kernels() {
  static const BatchKernels& chosen = [] () -> const BatchKernels& {
    const std::vector<const BatchKernels*> available = available_batch_kernels();
    const char* forced = std::getenv("BALLPIT_KERNELS");
    if (!forced || !*forced) return *available.back();
    for (const BatchKernels* k : available)
      if (k->name == forced) return *k;
    std::string names;
    for (const BatchKernels* k : available) names += (names.empty() ? "" : ", ") + std::string(k->name);
    throw Error("BALLPIT_KERNELS=" + std::string(forced) + ": this build and CPU run only " + names);
  }();
  return chosen;
}

}  // namespace ballpit
