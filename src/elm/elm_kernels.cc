// Run-time choice of the ELM kernels (kernels.h).
#include "elm/elm_kernels.h"

namespace gyrodrift::elm::internal {

// kernels_avx2.cc: the AVX2 + FMA table, or nullptr when that file was built without them.
const Kernels* Avx2KernelTableIfBuilt();

const Kernels* Avx2Kernels() {
  static const Kernels* const kernels = []() -> const Kernels* {
#if defined(GYRODRIFT_ELM_FORCE_BASELINE_KERNELS)
    // A build that tests the baseline path end to end on a CPU with AVX2.
    return nullptr;
#elif (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
    __builtin_cpu_init();
    // GCC's and Clang's checks include the operating system's support for the AVX state.
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
      return Avx2KernelTableIfBuilt();
    }
#endif
    return nullptr;
  }();
  return kernels;
}

const Kernels& ActiveKernels() {
  static const Kernels& kernels = Avx2Kernels() != nullptr ? *Avx2Kernels() : BaselineKernels();
  return kernels;
}

}  // namespace gyrodrift::elm::internal
