#include "allan/kernels.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gyrodrift::allan::internal {
namespace {

constexpr int kLanes = 8;
// Chunk of i processed for a whole group of factors before moving on, so the three streams
// x[i], x[i+m], x[i+2m] of consecutive factors (3 x 8 KiB) stay in the 32 KiB L1; 2048 spilled
// to L2 and was about 20 % slower. A multiple of kLanes, so lane (i mod kLanes) assignment is the
// same for every grouping.
constexpr std::int64_t kChunk = 1024;

// acc[l] += sum over i in [begin, end) with i = begin + l (mod kLanes) of d_i^2; begin is a
// multiple of kLanes. Separate lanes keep the floating-point order fixed while the compiler maps
// them onto vector registers (target_clones picks AVX2 when the CPU has it; the arithmetic is the
// same, so the bits are too).
__attribute__((target_clones("avx2", "default"))) void AccumulateLanes(const double* __restrict x0,
                                                                       const double* __restrict x1,
                                                                       const double* __restrict x2,
                                                                       std::int64_t count,
                                                                       double* __restrict acc) {
  double a[kLanes];
  for (int l = 0; l < kLanes; ++l) a[l] = acc[l];
  std::int64_t i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const double d = x2[i + l] - 2.0 * x1[i + l] + x0[i + l];
      a[l] += d * d;
    }
  }
  for (int l = 0; i < count; ++i, ++l) {
    const double d = x2[i] - 2.0 * x1[i] + x0[i];
    a[l] += d * d;
  }
  for (int l = 0; l < kLanes; ++l) acc[l] = a[l];
}

// Four consecutive factors m, m+1, m+2, m+3 over a full chunk: x[i] is loaded once for all four
// (a quarter of the loads saved). Each factor's terms and lanes are exactly those of
// AccumulateLanes, so the sums are the same bits.
__attribute__((target_clones("avx2", "default"))) void AccumulateLanes4(
    const double* __restrict x0, const double* __restrict x1, const double* __restrict x2,
    std::int64_t count, double* __restrict acc0, double* __restrict acc1, double* __restrict acc2,
    double* __restrict acc3) {
  double a0[kLanes], a1[kLanes], a2[kLanes], a3[kLanes];
  for (int l = 0; l < kLanes; ++l) {
    a0[l] = acc0[l];
    a1[l] = acc1[l];
    a2[l] = acc2[l];
    a3[l] = acc3[l];
  }
  // x1 + j and x2 + 2j are the streams of factor m + j.
  for (std::int64_t i = 0; i + kLanes <= count; i += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const double base = x0[i + l];
      const double d0 = x2[i + l] - 2.0 * x1[i + l] + base;
      const double d1 = x2[i + l + 2] - 2.0 * x1[i + l + 1] + base;
      const double d2 = x2[i + l + 4] - 2.0 * x1[i + l + 2] + base;
      const double d3 = x2[i + l + 6] - 2.0 * x1[i + l + 3] + base;
      a0[l] += d0 * d0;
      a1[l] += d1 * d1;
      a2[l] += d2 * d2;
      a3[l] += d3 * d3;
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    acc0[l] = a0[l];
    acc1[l] = a1[l];
    acc2[l] = a2[l];
    acc3[l] = a3[l];
  }
}

double ReduceLanes(const double* acc) {
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

}  // namespace

void OverlappingSecondDifferenceSums(const double* x, std::int64_t n, const std::int64_t* ms,
                                     int count, double* out) {
  if (count <= 0) return;
  // One sweep over i for every factor: factor k's stream x[i + 2 m_k] is factor k+1's x[i + m]
  // on an octave grid, and x[i] is everyone's, so a chunk of the phase comes from memory once for
  // all the factors whose streams are within cache reach of each other, instead of three times
  // per factor in a pass of its own (at 1e7 samples the per-factor passes ran from DRAM and cost
  // 3x the octave sweep; docs/performance.md).
  std::vector<double> acc(static_cast<size_t>(count) * kLanes, 0.0);
  auto lanes = [&](int k) { return acc.data() + static_cast<size_t>(k) * kLanes; };
  int active = count;  // factors with terms left in the current chunk (ms ascending)
  for (std::int64_t c = 0; c < n - 2 * ms[0]; c += kChunk) {
    while (c >= n - 2 * ms[active - 1]) --active;
    for (int k = 0; k < active;) {
      const std::int64_t m = ms[k];
      // Four consecutive factors whose chunk is complete: one shared pass.
      if (k + 4 <= active && ms[k + 3] == m + 3 && c + kChunk <= n - 2 * (m + 3)) {
        AccumulateLanes4(x + c, x + c + m, x + c + 2 * m, kChunk, lanes(k), lanes(k + 1),
                         lanes(k + 2), lanes(k + 3));
        k += 4;
        continue;
      }
      const std::int64_t end = std::min(c + kChunk, n - 2 * m);
      AccumulateLanes(x + c, x + c + m, x + c + 2 * m, end - c, lanes(k));
      ++k;
    }
  }
  for (int k = 0; k < count; ++k) out[k] = ReduceLanes(lanes(k));
}

double AdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s) {
  const std::int64_t terms = (n - 1) / m - 1;
  double sum = 0.0;
  for (std::int64_t k = 0; k < terms; ++k) {
    const std::int64_t i = k * m;
    const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    sum += d * d;
  }
  return sum / (2.0 * static_cast<double>(terms) * tau_s * tau_s);
}

double HdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s) {
  const std::int64_t terms = (n - 1) / m - 2;
  double sum = 0.0;
  for (std::int64_t k = 0; k < terms; ++k) {
    const std::int64_t i = k * m;
    const double d = x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i];
    sum += d * d;
  }
  return sum / (6.0 * static_cast<double>(terms) * tau_s * tau_s);
}

double OhdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s) {
  const std::int64_t terms = n - 3 * m;
  double acc[4] = {0, 0, 0, 0};
  std::int64_t i = 0;
  for (; i + 4 <= terms; i += 4) {
    for (int l = 0; l < 4; ++l) {
      const std::int64_t j = i + l;
      const double d = x[j + 3 * m] - 3.0 * x[j + 2 * m] + 3.0 * x[j + m] - x[j];
      acc[l] += d * d;
    }
  }
  for (; i < terms; ++i) {
    const double d = x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i];
    acc[0] += d * d;
  }
  const double sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  return sum / (6.0 * static_cast<double>(terms) * tau_s * tau_s);
}

double MdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s) {
  // w_j = sum_{i=j}^{j+m-1} (x[i+2m] - 2x[i+m] + x[i]), slid along j. The running sum only ever
  // holds second differences (small numbers), so its rounding stays at the level of one term.
  const std::int64_t terms = n - 3 * m + 1;
  auto d2 = [&](std::int64_t i) { return x[i + 2 * m] - 2.0 * x[i + m] + x[i]; };
  double w = 0.0;
  for (std::int64_t i = 0; i < m; ++i) w += d2(i);
  double sum = w * w;
  for (std::int64_t j = 1; j < terms; ++j) {
    w += d2(j + m - 1) - d2(j - 1);
    sum += w * w;
  }
  const double md = static_cast<double>(m);
  return sum / (2.0 * md * md * tau_s * tau_s * static_cast<double>(terms));
}

std::vector<double> ExtendForTotdev(const double* x, std::int64_t n) {
  // x*(1-j) = 2x(1) - x(1+j), x*(N+j) = 2x(N) - x(N-j), j = 1..N-2 (NIST SP 1065, eq. 25).
  const std::int64_t pad = n - 2;
  std::vector<double> e(static_cast<size_t>(n + 2 * pad));
  for (std::int64_t j = 1; j <= pad; ++j) e[pad - j] = 2.0 * x[0] - x[j];
  for (std::int64_t i = 0; i < n; ++i) e[pad + i] = x[i];
  for (std::int64_t j = 1; j <= pad; ++j) e[pad + n - 1 + j] = 2.0 * x[n - 1] - x[n - 1 - j];
  return e;
}

double TotdevVariance(const std::vector<double>& extended, std::int64_t n, std::int64_t m,
                      double tau_s) {
  const std::int64_t pad = n - 2;
  const double* e = extended.data() + pad;  // e[i] = x[i] for 0 <= i < n
  double acc[4] = {0, 0, 0, 0};
  const std::int64_t terms = n - 2;
  std::int64_t k = 0;
  for (; k + 4 <= terms; k += 4) {
    for (int l = 0; l < 4; ++l) {
      const std::int64_t i = 1 + k + l;
      const double d = e[i - m] - 2.0 * e[i] + e[i + m];
      acc[l] += d * d;
    }
  }
  for (; k < terms; ++k) {
    const std::int64_t i = 1 + k;
    const double d = e[i - m] - 2.0 * e[i] + e[i + m];
    acc[0] += d * d;
  }
  const double sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  return sum / (2.0 * tau_s * tau_s * static_cast<double>(terms));
}

}  // namespace gyrodrift::allan::internal
