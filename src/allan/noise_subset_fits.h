// Private: the least-squares fits behind the noise fit (noise_fit.cc): a weighted non-negative fit
// in variance for the start values, and every subset of the five terms fitted in log variance.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <vector>

#include "allan/noise_terms_model.h"

namespace gyrodrift::allan::internal {

struct NnlsFit {
  std::array<double, kTerms> coef{};
  Eigen::MatrixXd cov;  // of the active coefficients, in `active` order
  std::vector<int> active;
  double chi2 = 0.0;
  bool ok = false;
};

// Exact non-negative least squares min |a c - b| over the terms in `allowed`.
NnlsFit SolveNnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, unsigned allowed);

// A curve in log variance. An AVAR estimate with EDF nu is AVAR chi2_nu / nu, so its logarithm has
// mean ln AVAR + psi(nu/2) - ln(nu/2) and variance psi'(nu/2) whatever its value. Fitting the
// variances themselves with weights from the measured values overweights points that came out
// low, which biases the long-tau terms (K, R) low by about one standard error; weights from the
// model instead let the model float above the tail of real curves. The log fit has neither
// problem, and it minimises the misfit one sees on a log-log plot.
struct LogCurve {
  Eigen::MatrixXd columns;  // n x 5 model columns
  Eigen::VectorXd target;   // ln(var) - (psi(nu/2) - ln(nu/2))
  Eigen::VectorXd sd;       // sqrt(psi'(nu/2))
};

// The log curve of variances `var` with EDF `edf` (> 0) per point.
LogCurve MakeLogCurve(const Eigen::MatrixXd& columns, const Eigen::VectorXd& var,
                      const Eigen::VectorXd& edf);

struct SubsetFit {
  std::array<double, kTerms> coef{};                      // 0 for terms outside the subset
  double chi2 = std::numeric_limits<double>::infinity();  // sum of squared standardised residuals
  Eigen::MatrixXd jacobian;  // d residual / d ln c_j at the optimum, active terms in index order
  bool ok = false;
};

using SubsetFits = std::array<SubsetFit, 1u << kTerms>;  // indexed by the mask of the terms

// Every subset of the five terms (at most n terms) fitted to the log curve d; a (n x 5) and b are
// the weighted variance problem whose non-negative fits give start values, var the variances.
SubsetFits FitAllSubsets(const LogCurve& d, const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                         const Eigen::VectorXd& var);

}  // namespace gyrodrift::allan::internal
