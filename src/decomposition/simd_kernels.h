// Private: the per-sample loops of one sift in vector form, with a run-time choice between the
// SSE2 build (every x86-64) and an AVX2 build where the processor has it. Both paths do the
// same IEEE operations lane by lane, so they give the same bits (tested); the choice only
// changes the speed. Cost: O(n) per call, no allocation.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

namespace gyrodrift::decomposition::internal {

// A fitted not-a-knot spline on integer node times (see spline.h): m nodes t, y, the divided
// differences dd, slopes and the per-piece coefficients c1, c2 (v = ((c1 h + c2) h + slope) h + y).
struct SplineView {
  size_t m = 0;
  const double* t = nullptr;
  const double* y = nullptr;
  const double* dd = nullptr;
  const double* c1 = nullptr;
  const double* c2 = nullptr;
  const double* slope = nullptr;
};

// Evaluates at t = 1..n into out (room for n + kSimdPadding values; the tail is scratch).
void SimdEvaluate(const SplineView& s, Eigen::Index n, double* out);
// next[i] = h[i] - (lower[i] + s(i)) / 2 for i < n; all three with room for n + kSimdPadding.
void SimdEvaluateSift(const SplineView& s, Eigen::Index n, const double* lower, const double* h,
                      double* next);
inline constexpr Eigen::Index kSimdPadding = 8;

// Output of the strict-extremum scan: 0-based indices (arrays of capacity >= n) and counts.
struct ExtremaScan {
  int* indmin = nullptr;
  int* indmax = nullptr;
  int nmin = 0;
  int nmax = 0;
  std::int64_t sign_changes = 0;  // pairs with x[i] x[i+1] < 0 (when asked)
  bool has_zero = false;          // some sample is exactly zero (when asked)
};
// Strict extrema of x (emd.m's sign test on the first difference); returns true when some first
// difference is exactly zero (plateaus to look at). With zero_crossings, also fills
// sign_changes and has_zero.
bool SimdFindStrictExtrema(const double* x, Eigen::Index n, bool zero_crossings, ExtremaScan* out);

// One sift under the Rilling-Flandrin rule from the two envelopes: next[i] = h[i] - mean[i] and
// the counts of the stopping test on ratio = |mean| / amplitude (mean = (lo + hi) / 2,
// amplitude = |hi - lo| / 2), for i < n.
struct RillingCounts {
  std::int64_t above1 = 0;  // samples with ratio > threshold1
  bool above2 = false;      // some sample has ratio > threshold2
};
RillingCounts SimdRillingSift(const double* lo, const double* hi, const double* h, double* next,
                              Eigen::Index n, double threshold1, double threshold2);

// Which build runs: kAuto picks AVX2 when the processor has it. For tests and benchmarks.
enum class SimdPath { kAuto, kBaseline, kAvx2 };
bool SimdAvx2Available();
void SetSimdPath(SimdPath path);  // kAvx2 without the hardware falls back to the baseline

}  // namespace gyrodrift::decomposition::internal
