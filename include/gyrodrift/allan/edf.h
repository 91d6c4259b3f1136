// Equivalent degrees of freedom of the Allan-variance family and their chi-square confidence
// intervals, as Compute() (allan.h) attaches them to every point, and the noise type at each
// averaging time that the EDF depends on (lag-1 autocorrelation).
//
// References
//   C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
//     differences", 35th PTTI (2003): EDF of ADEV/OADEV/MDEV/TDEV/HDEV/OHDEV.
//   W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065 (2008): EDF of TOTDEV
//     (table 7), the simple formulas of table 5, chi-square intervals (eq. 45).
//   W. J. Riley, C. A. Greenhall, "Power law noise identification using the lag 1
//     autocorrelation", EFTF 2004.
// Cost: O(1) per point: at most 100 terms of Greenhall & Riley's basic sum (their J_max).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "gyrodrift/allan/allan.h"

namespace gyrodrift::allan {

// Equivalent degrees of freedom of deviation `d` at factor m for n_phase points and noise alpha:
// Greenhall & Riley 2003 for ADEV/OADEV/MDEV/TDEV/HDEV/OHDEV, NIST SP 1065 table 7 for TOTDEV
// (alpha = 0, -1, -2; SP 1065 table 5 simple formulas for alpha = 2, 1, as Stable32).
double EquivalentDof(Deviation d, int alpha, std::int64_t m, Eigen::Index n_phase);
// Quantile of the chi-square distribution with `dof` (> 0, real) degrees of freedom.
double ChiSquareQuantile(double p, double dof);
// Regularized lower incomplete gamma P(a, x).
double RegularizedGammaP(double a, double x);
// [lo, hi] of a deviation with `edf` degrees of freedom at two-sided confidence `confidence`
// (NIST SP 1065 eq. 45).
void ConfidenceInterval(double dev, double edf, double confidence, double* lo, double* hi);

// Lag-1 autocorrelation noise identification (Riley & Greenhall 2004) at averaging factor m.
// `phase` is the internal phase (angle) series; for rate data the m-averaged rates are analysed,
// for angle data the m-decimated phase. dmax = 2 for Allan-type, 3 for Hadamard-type estimators.
// Returns nullopt when fewer than 30 points remain. Cost O(N / m), no copy of the series unless
// differencing is needed (rho >= 0.25 at d = 0).
std::optional<int> IdentifyAlpha(const Eigen::Ref<const Eigen::VectorXd>& phase, std::int64_t m,
                                 DataType type, int dmax);

}  // namespace gyrodrift::allan
