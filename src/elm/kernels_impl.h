// Body of the ELM kernels (elm_kernels.h), included once by kernels_baseline.cc and once by
// kernels_avx2.cc. Before including it a file defines
//   Eigen                          a private name for Eigen's namespace in that file, so that
//                                  its Eigen instantiations (built with that file's instruction
//                                  set) never merge with the rest of the program's at link time;
//   GYRODRIFT_ELM_KERNEL_FMA       1 to use fused multiply-adds (the file is built with -mfma);
//   GYRODRIFT_ELM_KERNEL_TABLE     the name of the function returning this file's table.
// Everything else here has internal linkage. Do not include headers that define inline
// functions used here from other files of the project (elm_kernels.h is plain data only).
//
// The hidden-layer and output products are hand-written rather than Eigen products: a matrix
// product library picks its summation order from the matrix shapes (a one-row product takes a
// different path from a 4096-row one), and the ELM wants each H_ij and each prediction to be the
// same bits whether its row is evaluated alone or in a block. Every element here is computed by
// the same sequence of vector operations, in whichever lane and tile it falls (rows past the end
// of a tile repeat the last row and are not stored). The Gram matrix, the leave-one-out products
// and the eigendecompositions only need the same bits for the same block shapes, which N alone
// fixes, so they stay with Eigen's tuned products.
#include <immintrin.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstring>

#include "elm/elm_kernels.h"

namespace {

using gyrodrift::elm::internal::Kernels;
using gyrodrift::elm::internal::LooPlanView;

// One SIMD register of doubles: four with AVX, two with SSE2 (GCC vector extensions, so the same
// source serves both builds).
constexpr int kLanes = GYRODRIFT_ELM_KERNEL_FMA ? 4 : 2;
typedef double Vec __attribute__((vector_size(kLanes * sizeof(double))));
typedef long long VecI __attribute__((vector_size(kLanes * sizeof(long long))));

// Row vectors per tile of the hidden-layer kernel: 2 row vectors x 4 units = 8 accumulators,
// which with the inputs and a weight fit the 16 vector registers.
constexpr int kRowVecs = 2;
constexpr long kTileRows = kLanes * kRowVecs;
constexpr int kTileUnits = 4;

inline Vec Splat(double x) {
#if GYRODRIFT_ELM_KERNEL_FMA
  return _mm256_set1_pd(x);
#else
  return _mm_set1_pd(x);
#endif
}
inline Vec Load(const double* p) {
  Vec v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void Store(double* p, Vec v) { std::memcpy(p, &v, sizeof(v)); }
inline long Min(long a, long b) { return a < b ? a : b; }

inline Vec MulAdd(Vec a, Vec b, Vec c) {
#if GYRODRIFT_ELM_KERNEL_FMA
  return _mm256_fmadd_pd(a, b, c);
#else
  return a * b + c;
#endif
}

inline Vec Clamp(Vec x, double lo, double hi) {
  x = x < Splat(lo) ? Splat(lo) : x;
  return x > Splat(hi) ? Splat(hi) : x;
}

// exp(x) for x in [-708, 708] (so 2^n below is a normal number), within about 1 ulp: the
// Cody-Waite reduction x = n ln2 + r, |r| <= ln2 / 2 (ln2 split in a 32-bit head, exact times
// any |n| <= 1022, and a tail), then the Taylor polynomial of degree 13, whose truncation error
// (ln2/2)^14 / 14! = 4e-18 is below the rounding of the result.
inline Vec Exp(Vec x) {
  constexpr double kLog2e = 1.4426950408889634074;
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // 0x1.62e42feep-1
  constexpr double kLn2Lo = 1.90821492927058770002e-10;
  // Adding 1.5 * 2^52 rounds to an integer and leaves it in the low bits of the mantissa.
  constexpr double kShift = 6755399441055744.0;
  const Vec t = MulAdd(x, Splat(kLog2e), Splat(kShift));
  const Vec n = t - Splat(kShift);
  Vec r = MulAdd(n, Splat(-kLn2Hi), x);
  r = MulAdd(n, Splat(-kLn2Lo), r);
  constexpr double kInvFactorial[14] = {1.0,
                                        1.0,
                                        1.0 / 2,
                                        1.0 / 6,
                                        1.0 / 24,
                                        1.0 / 120,
                                        1.0 / 720,
                                        1.0 / 5040,
                                        1.0 / 40320,
                                        1.0 / 362880,
                                        1.0 / 3628800,
                                        1.0 / 39916800,
                                        1.0 / 479001600,
                                        1.0 / 6227020800};
  Vec p = Splat(kInvFactorial[13]);
  for (int k = 12; k >= 0; --k) p = MulAdd(p, r, Splat(kInvFactorial[k]));
  // Vector casts reinterpret the bits: t - kShift as integers is n.
  const VecI two_n = ((VecI)t - (VecI)Splat(kShift) + 1023) << 52;
  return p * (Vec)two_n;
}

// 1 / (1 + exp(-z)). For z > 40, exp(-z) < 2^-57 and 1 + exp(-z) rounds to 1 anyway; for
// z < -708 the result is held at 1 / (1 + e^708), about 3e-308, instead of decaying further.
inline Vec Sigmoid(Vec z) { return Splat(1.0) / (Splat(1.0) + Exp(Clamp(-z, -40.0, 708.0))); }

template <int kActivation>
inline Vec Activate(Vec z, double rbf_gamma) {
  using namespace gyrodrift::elm::internal;
  if constexpr (kActivation == kKernelSigmoid) {
    return Sigmoid(z);
  } else if constexpr (kActivation == kKernelTanh) {
    for (int l = 0; l < kLanes; ++l) z[l] = std::tanh(z[l]);
    return z;
  } else if constexpr (kActivation == kKernelSine) {
    for (int l = 0; l < kLanes; ++l) z[l] = std::sin(z[l]);
    return z;
  } else if constexpr (kActivation == kKernelRbf) {
    // z is the squared distance (>= 0); below e^-708 the unit is held at e^-708.
    return Exp(Clamp(Splat(-rbf_gamma) * z, -708.0, 0.0));
  } else {
    return z;
  }
}

// Loads rows row[0 .. kLanes-1] of a column; kContiguous when they are the consecutive rows
// from row[0] on.
template <bool kContiguous>
inline Vec LoadRows(const double* column, const long* row) {
  if constexpr (kContiguous) return Load(column + row[0]);
  Vec v;
  for (int l = 0; l < kLanes; ++l) v[l] = column[row[l]];
  return v;
}

template <bool kFull>
inline void StoreRows(double* column, long first, long valid, Vec v) {
  if (kFull || valid >= kLanes) {
    Store(column + first, v);
  } else {
    for (long l = 0; l < valid; ++l) column[first + l] = v[l];
  }
}

// One tile of kTileRows rows (row[] holds their indices, the last one repeated past the end when
// not kFull) for every unit, kTileUnits units at a time.
template <int kActivation, bool kFull>
inline void HiddenTile(const double* xs, long ld_xs, long rows, long i0, const long* row, long d,
                       const double* w, const double* b, long hidden, double* out, long ld_out) {
  constexpr bool kDistance = kActivation == gyrodrift::elm::internal::kKernelRbf;
  const double inv_d = 1.0 / static_cast<double>(d > 0 ? d : 1);
  for (long j0 = 0; j0 < hidden; j0 += kTileUnits) {
    const double* wu[kTileUnits];
    Vec acc[kTileUnits][kRowVecs];
    for (int u = 0; u < kTileUnits; ++u) {
      const long j = Min(j0 + u, hidden - 1);
      wu[u] = w + j * d;
      for (int v = 0; v < kRowVecs; ++v) acc[u][v] = Splat(kDistance ? 0.0 : b[j]);
    }
    for (long k = 0; k < d; ++k) {
      const double* column = xs + k * ld_xs;
      Vec x[kRowVecs];
      for (int v = 0; v < kRowVecs; ++v) x[v] = LoadRows<kFull>(column, row + v * kLanes);
      for (int u = 0; u < kTileUnits; ++u) {
        const Vec wk = Splat(wu[u][k]);
        for (int v = 0; v < kRowVecs; ++v) {
          if constexpr (kDistance) {
            const Vec diff = x[v] - wk;
            acc[u][v] = MulAdd(diff, diff, acc[u][v]);
          } else {
            acc[u][v] = MulAdd(x[v], wk, acc[u][v]);
          }
        }
      }
    }
    for (int u = 0; u < kTileUnits && j0 + u < hidden; ++u) {
      const long j = j0 + u;
      for (int v = 0; v < kRowVecs; ++v) {
        const long first = i0 + v * kLanes;
        if (!kFull && first >= rows) break;
        StoreRows<kFull>(out + j * ld_out, first, rows - first,
                         Activate<kActivation>(acc[u][v], b[j] * inv_d));
      }
    }
  }
}

template <int kActivation>
void HiddenImpl(const double* xs, long ld_xs, long rows, long d, const double* w, const double* b,
                long hidden, double* out, long ld_out) {
  long row[kTileRows];
  long i0 = 0;
  for (; i0 + kTileRows <= rows; i0 += kTileRows) {
    for (long r = 0; r < kTileRows; ++r) row[r] = i0 + r;
    HiddenTile<kActivation, true>(xs, ld_xs, rows, i0, row, d, w, b, hidden, out, ld_out);
  }
  if (i0 < rows) {
    for (long r = 0; r < kTileRows; ++r) row[r] = Min(i0 + r, rows - 1);
    HiddenTile<kActivation, false>(xs, ld_xs, rows, i0, row, d, w, b, hidden, out, ld_out);
  }
}

void Hidden(int activation, const double* xs, long ld_xs, long rows, long d, const double* w,
            const double* b, long hidden, double* out, long ld_out) {
  using namespace gyrodrift::elm::internal;
  if (rows <= 0 || hidden <= 0) return;
  switch (activation) {
    case kKernelSigmoid:
      return HiddenImpl<kKernelSigmoid>(xs, ld_xs, rows, d, w, b, hidden, out, ld_out);
    case kKernelTanh:
      return HiddenImpl<kKernelTanh>(xs, ld_xs, rows, d, w, b, hidden, out, ld_out);
    case kKernelSine:
      return HiddenImpl<kKernelSine>(xs, ld_xs, rows, d, w, b, hidden, out, ld_out);
    case kKernelRbf:
      return HiddenImpl<kKernelRbf>(xs, ld_xs, rows, d, w, b, hidden, out, ld_out);
    default:
      return HiddenImpl<kKernelLinear>(xs, ld_xs, rows, d, w, b, hidden, out, ld_out);
  }
}

constexpr int kOutputVecs = 4;
constexpr long kOutputRows = kOutputVecs * kLanes;

template <bool kFull>
inline void OutputTile(const double* h, long ld_h, long rows, long i0, const long* row, long hidden,
                       const double* beta_k, double* y_k) {
  Vec acc[kOutputVecs];
  for (int v = 0; v < kOutputVecs; ++v) acc[v] = Splat(0.0);
  for (long j = 0; j < hidden; ++j) {
    const double* column = h + j * ld_h;
    const Vec bj = Splat(beta_k[j]);
    for (int v = 0; v < kOutputVecs; ++v) {
      acc[v] = MulAdd(LoadRows<kFull>(column, row + v * kLanes), bj, acc[v]);
    }
  }
  for (int v = 0; v < kOutputVecs; ++v) {
    const long first = i0 + v * kLanes;
    if (!kFull && first >= rows) break;
    StoreRows<kFull>(y_k, first, rows - first, acc[v]);
  }
}

void Output(const double* h, long ld_h, long rows, long hidden, const double* beta, long outputs,
            double* y, long ld_y) {
  long row[kOutputRows];
  for (long k = 0; k < outputs; ++k) {
    long i0 = 0;
    for (; i0 + kOutputRows <= rows; i0 += kOutputRows) {
      for (long r = 0; r < kOutputRows; ++r) row[r] = i0 + r;
      OutputTile<true>(h, ld_h, rows, i0, row, hidden, beta + k * hidden, y + k * ld_y);
    }
    if (i0 < rows) {
      for (long r = 0; r < kOutputRows; ++r) row[r] = Min(i0 + r, rows - 1);
      OutputTile<false>(h, ld_h, rows, i0, row, hidden, beta + k * hidden, y + k * ld_y);
    }
  }
}

using ConstStrided = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

void Gram(const double* h, long ld_h, long rows, long cols, double* g) {
  const ConstStrided hm(h, rows, cols, Eigen::OuterStride<>(ld_h));
  Eigen::Map<Eigen::MatrixXd> gm(g, cols, cols);
  gm.triangularView<Eigen::Lower>().setZero();
  gm.selfadjointView<Eigen::Lower>().rankUpdate(hm.transpose());
}

void SymmetricEigen(const double* a, long lda, long n, double* values, double* vectors) {
  const ConstStrided am(a, n, n, Eigen::OuterStride<>(lda));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(am);
  if (eig.info() != Eigen::Success) {
    // Reported as NaN eigenvalues: the caller's condition test then skips the candidate.
    Eigen::Map<Eigen::VectorXd>(values, n).setConstant(__builtin_nan(""));
    Eigen::Map<Eigen::MatrixXd>(vectors, n, n).setZero();
    return;
  }
  Eigen::Map<Eigen::VectorXd>(values, n) = eig.eigenvalues();
  Eigen::Map<Eigen::MatrixXd>(vectors, n, n) = eig.eigenvectors();
}

void Loo(const double* h, long ld_h, long rows, const double* t, long ld_t, long outputs,
         const LooPlanView* plans, long num_plans, double* p_buffer, double* fitted_buffer,
         double* hat_buffer, double* sums) {
  const ConstStrided tm(t, rows, outputs, Eigen::OuterStride<>(ld_t));
  for (long q = 0; q < num_plans; ++q) {
    const LooPlanView& plan = plans[q];
    const long l = plan.hidden;
    const long active = plan.active;
    if (active == 0) continue;
    const ConstStrided hl(h, rows, l, Eigen::OuterStride<>(ld_h));
    Eigen::Map<Eigen::MatrixXd> p(p_buffer, rows, l);
    Eigen::Map<Eigen::MatrixXd> fitted(fitted_buffer, rows, active * outputs);
    Eigen::Map<Eigen::MatrixXd> hat(hat_buffer, rows, active);
    p.noalias() = hl * Eigen::Map<const Eigen::MatrixXd>(plan.vectors, l, l);
    fitted.noalias() = p * Eigen::Map<const Eigen::MatrixXd>(plan.fit_weights, l, active * outputs);
    p = p.array().square().matrix();
    hat.noalias() = p * Eigen::Map<const Eigen::MatrixXd>(plan.hat_weights, l, active);
    for (long a = 0; a < active; ++a) {
      for (long k = 0; k < outputs; ++k) {
        double s = 0.0;
        for (long i = 0; i < rows; ++i) {
          const double leverage_gap = 1.0 - hat(i, a);
          // h_ii = 1 means the row is interpolated whatever its target: its leave-one-out
          // error is undefined, reported as +inf.
          const double e = leverage_gap > 0.0
                               ? (tm(i, k) - fitted(i, a * outputs + k)) / leverage_gap
                               : __builtin_inf();
          s += e * e;
        }
        sums[plan.offset + a * outputs + k] = s;
      }
    }
  }
}

}  // namespace

namespace gyrodrift::elm::internal {

const Kernels& GYRODRIFT_ELM_KERNEL_TABLE() {
  static const Kernels table{GYRODRIFT_ELM_KERNEL_FMA ? "avx2+fma" : "baseline",
                             &Hidden,
                             &Output,
                             &Gram,
                             &SymmetricEigen,
                             &Loo};
  return table;
}

}  // namespace gyrodrift::elm::internal
