// The ELM kernels for CPUs with AVX2 and FMA. The build compiles this file alone with
// -mavx2 -mfma (CMakeLists.txt, x86-64 with GCC or Clang); elsewhere it provides no table.
// Only ActiveKernels() (kernels.cc) calls into it, after checking the CPU.
#include "elm/elm_kernels.h"

#if defined(__AVX2__) && defined(__FMA__)

#define Eigen gyrodrift_elm_avx2_eigen
#define GYRODRIFT_ELM_KERNEL_FMA 1
#define GYRODRIFT_ELM_KERNEL_TABLE Avx2KernelTable
#include "elm/kernels_impl.h"

namespace gyrodrift::elm::internal {
const Kernels* Avx2KernelTableIfBuilt() { return &Avx2KernelTable(); }
}  // namespace gyrodrift::elm::internal

#else

namespace gyrodrift::elm::internal {
const Kernels* Avx2KernelTableIfBuilt() { return nullptr; }
}  // namespace gyrodrift::elm::internal

#endif
