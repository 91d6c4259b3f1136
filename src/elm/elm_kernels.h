// The ELM's compute kernels behind a plain-pointer interface, built twice: once for baseline
// x86-64 (SSE2) and once with AVX2 + FMA (kernels_avx2.cc, compiled with -mavx2 -mfma), and
// picked at run time by what the CPU supports. Everything else in the module calls them through
// ActiveKernels().
//
// Why this header has no Eigen: the AVX2 translation unit must not instantiate any inline or
// template function that another translation unit also instantiates (the linker keeps one copy
// of such a function for the whole program, and it might keep the AVX2 one, which then crashes
// on a CPU without AVX2). So the kernel files include Eigen under a private namespace name (see
// kernels_impl.h) and exchange only pointers and sizes with the rest of the module.
//
// Bits: each kernel fixes its own order of floating-point operations, so the results depend on
// the inputs alone, never on the thread count, the block size or the position of a row in a
// block. The AVX2 kernels use fused multiply-adds and the baseline kernels do not, so the two
// agree only to rounding (a few ulps per product, about 1e-13 relative in a fitted model); a
// model fitted or evaluated on a CPU with AVX2 can differ in the last bits from the same run on
// one without.
//
// Matrices are column-major: element (i, j) of a matrix with leading dimension ld is p[i + j*ld].
#pragma once

namespace gyrodrift::elm::internal {

// Activation codes of the kernels; equal to static_cast<int>(Activation) (checked in hidden.cc).
inline constexpr int kKernelSigmoid = 0;
inline constexpr int kKernelTanh = 1;
inline constexpr int kKernelSine = 2;
inline constexpr int kKernelRbf = 3;
inline constexpr int kKernelLinear = 4;

// One candidate network size of the leave-one-out grid (see loo.cc). No member initialisers:
// the struct must stay trivial, so that no constructor is instantiated in the kernel files.
struct LooPlanView {
  long hidden;                // L
  long active;                // number of evaluated C values, A
  const double* vectors;      // V, L x L (eigenvectors of the leading Gram block)
  const double* fit_weights;  // L x (A m): z_jk / (lambda_j + delta_c), c-major
  const double* hat_weights;  // L x A: 1 / (lambda_j + delta_c)
  long offset;                // first of its A m entries in the sums vector
};

struct Kernels {
  const char* name;  // "avx2+fma" or "baseline"

  // out (rows x L) = g(z) with z_ij = b_j + sum_k xs_ik w_kj (k ascending) for sigmoid, tanh,
  // sine and linear units, and g = exp(-b_j / d * sum_k (xs_ik - w_kj)^2) for RBF units.
  // xs is rows x d, w is d x L (leading dimension d), b has L entries.
  void (*hidden)(int activation, const double* xs, long ld_xs, long rows, long d, const double* w,
                 const double* b, long hidden, double* out, long ld_out);

  // y (rows x m) = h (rows x L) * beta (L x m, leading dimension L), each entry summed over j
  // in ascending order starting from 0.
  void (*output)(const double* h, long ld_h, long rows, long hidden, const double* beta,
                 long outputs, double* y, long ld_y);

  // g (c x c, leading dimension c) = lower triangle of a^T a for a (rows x c); the strict upper
  // triangle of g is left as it was. A symmetric rank-k update: half the flops of a product.
  void (*gram)(const double* a, long ld_a, long rows, long cols, double* g);

  // Symmetric eigendecomposition of the leading n x n block of `a` (leading dimension lda,
  // lower triangle read): ascending eigenvalues and the orthonormal eigenvectors (n x n).
  void (*eigen)(const double* a, long lda, long n, double* values, double* vectors);

  // For one row block and every plan: sums[offset + a m + k] = sum over the rows of the squared
  // PRESS residual of output k for the a-th evaluated C (+inf where the hat diagonal is >= 1).
  // Workspace: p (rows x max L), fitted (rows x max A m), hat (rows x max A), each with leading
  // dimension `rows`.
  void (*loo)(const double* h, long ld_h, long rows, const double* t, long ld_t, long outputs,
              const LooPlanView* plans, long num_plans, double* p, double* fitted, double* hat,
              double* sums);
};

// The baseline kernels (any x86-64, or any other CPU).
const Kernels& BaselineKernels();
// The AVX2 + FMA kernels, or nullptr if they are not built in, the CPU lacks AVX2 or FMA, or
// the library was compiled with -DGYRODRIFT_ELM_FORCE_BASELINE_KERNELS (to test the baseline
// path end to end on an AVX2 machine).
const Kernels* Avx2Kernels();
// AVX2 + FMA when available, else baseline; decided once per process.
const Kernels& ActiveKernels();

}  // namespace gyrodrift::elm::internal
