// Correlation between overlapping Allan-variance estimates at different averaging times, for a
// Gaussian noise process with the IEEE 952 power-law spectrum. The noise fit (noise_fit.cc) uses
// it for the sandwich covariance of its terms and the design effect of its term tests: neighbouring
// points of a curve share most of their data, so treating them as independent makes the fitted
// terms' uncertainties several times too small and their significance too large.
//
// Theory. The overlapping estimator at factor m is the mean of D_k^2 / 2 over its n terms, where
// D is y filtered by the second difference of m-sample means, |H_m(f)|^2 =
// 4 sin^4(pi m f) / (m^2 sin^2(pi f)) (f in cycles per sample). For Gaussian y with one-sided
// spectrum G, Cov(D_i^2 at k, D_j^2 at l) = 2 c_ij(k - l)^2 (Isserlis' theorem; c_ij is the
// cross-covariance of the two filtered series), so for records much longer than the filters
//   Cov(avar_i, avar_j) ~ P_ij / (2 max(n_i, n_j)),  P_ij = integral_0^1/2 |H_i|^2 |H_j|^2 G^2 df
// and the correlation is P_ij / sqrt(P_ii P_jj) * sqrt(min(n_i, n_j) / max(n_i, n_j)).
// Spectra (one-sided, per sample, raw coefficients c = Q^2, N^2, B^2, K^2 in deg/h and s):
//   Q (white angle): 8 c sin^2(pi f) / tau0^2     N (white rate): 2 c / tau0
//   B (flicker rate): c / (pi f)                  K (random-walk rate): c tau0 / (2 sin^2(pi f))
// each of which integrates to its term of the IEEE 952 model (K: the discrete random walk, whose
// spectrum is c tau0 / (2 pi^2 f^2) at low f; the difference matters at the smallest factors). The
// rate ramp R is a trend, not a stationary noise, and contributes nothing here.
//
// Quadrature. Octave panels [f, 2f) from f = 1 / (1024 m_max) to 1/2, 1024 midpoints each, so the
// cost does not depend on the record length (about 4e4 points x T^2 / 2 for T averaging times).
// A filter that oscillates more than 32 times inside a panel is replaced by its envelope with
// sin^4 averaged (3/8); where both filters of a pair oscillate fast the mean of the product of
// their sin^4 factors is used (35/128 for the same m, 7/64 when one m is twice the other, 9/64
// otherwise: sin^4 x = (3 - 4 cos 2x + cos 4x) / 8 shares a harmonic only then).
#pragma once

#include <Eigen/Core>
#include <array>

namespace gyrodrift::allan {

// m: averaging factors (tau / tau0, > 0, need not be integers); coef: raw Q^2, N^2, B^2, K^2, R^2
// (R^2 unused); n_terms: number of terms of each estimate, or empty to take them as equal.
// Returns the T x T correlation matrix (identity when the spectrum is zero).
Eigen::MatrixXd AvarCorrelation(const Eigen::VectorXd& m, const std::array<double, 5>& coef,
                                double tau0_s, const Eigen::VectorXd& n_terms);

}  // namespace gyrodrift::allan
