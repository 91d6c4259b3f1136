// Private: the estimator kernels of allan.cc, on the internal phase series x (rate unit x s).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "gyrodrift/allan/allan.h"

namespace gyrodrift::allan::internal {

// Sums of squared second differences of x over the overlapping index range, for each factor in
// ms[0..count) (ascending): out[k] = sum_{i=0}^{n-2m-1} (x[i+2m] - 2 x[i+m] + x[i])^2, all factors
// in one sweep over i. The summation order depends only on i (fixed lanes, fixed chunk
// boundaries), never on which factors share a call, so any split of the factors over calls and
// threads gives the same bits.
void OverlappingSecondDifferenceSums(const double* x, std::int64_t n, const std::int64_t* ms,
                                     int count, double* out);

// IdentifyAlpha (edf.h) at every factor of ms, the same bits as one call per factor, in two
// sweeps over the phase in all (edf.cc).
std::vector<std::optional<int>> IdentifyAlphas(const Eigen::Ref<const Eigen::VectorXd>& phase,
                                               const std::vector<std::int64_t>& ms, DataType type,
                                               int dmax);

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
