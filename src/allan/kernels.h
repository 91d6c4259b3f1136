// Private: the estimator kernels of allan.cc, on the internal phase series x (rate unit x s).
#pragma once

#include <cstdint>
#include <vector>

namespace gyrodrift::allan::internal {

// Grouping of consecutive averaging factors in one pass of the overlapping kernel: at most this
// many factors, spanning at most this many samples (so their streams share cache lines).
constexpr int kOadevMaxGroup = 32;
constexpr std::int64_t kOadevMaxGroupSpan = 64;

// Sums of squared second differences of x over the overlapping index range, for each factor in
// ms[0..count): out[k] = sum_{i=0}^{n-2m-1} (x[i+2m] - 2 x[i+m] + x[i])^2. The summation order
// depends only on i (fixed lanes, fixed chunk boundaries), never on how the factors are grouped,
// so any grouping and any thread gives the same bits.
void OverlappingSecondDifferenceSums(const double* x, std::int64_t n, const std::int64_t* ms,
                                     int count, double* out);

// Deviation value (not yet squared-rooted: the variance) of each estimator at factor m.
double AdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s);
double HdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s);
double OhdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s);
double MdevVariance(const double* x, std::int64_t n, std::int64_t m, double tau_s);
// `extended` is x reflected at both ends (ExtendForTotdev); n is the original length.
double TotdevVariance(const std::vector<double>& extended, std::int64_t n, std::int64_t m,
                      double tau_s);
std::vector<double> ExtendForTotdev(const double* x, std::int64_t n);

}  // namespace gyrodrift::allan::internal
