// The ELM kernels for any CPU, built with the project's default flags (see elm_kernels.h).
#define Eigen gyrodrift_elm_baseline_eigen
#define GYRODRIFT_ELM_KERNEL_FMA 0
#define GYRODRIFT_ELM_KERNEL_TABLE BaselineKernels
#include "elm/kernels_impl.h"
