// Private: which terms the noise fit keeps (noise_fit.cc): the evidence for each term from the
// fits of every subset (noise_subset_fits.h), and the model selection by nested tests.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <utility>

#include "allan/noise_subset_fits.h"

namespace gyrodrift::allan::internal {

// The log-variance misfit of the subset fits treats the points as independent, but neighbouring
// points share most of their data (for white rate noise the OADEV variances at tau and 2 tau are
// correlated at about 0.7), so its differences between nested models are not chi-square with 1
// degree of freedom, and the model-based covariance of the fit is several times too small. Both are
// corrected with the correlation rho of the points for Gaussian noise with the fitted spectrum
// (avar_correlation.h): the covariance of ln c is the sandwich (J'J)^-1 J' rho J (J'J)^-1, and the
// rise of the misfit when term j is removed is divided by the design effect delta_j = sandwich_jj /
// (J'J)^-1_jj (the first-order Rao-Scott correction: under the smaller model the rise is delta_j
// chi2_1). When the reduced chi-square exceeds 1 (the model misses something: a drift, filtering, a
// noise type outside the five) the covariance is widened, and the rise divided, by it, so that a
// poor fit does not make every term look significant. (Generalised least squares, whitening the
// residuals with rho, would make the misfit chi-square directly, but it amplifies every departure
// of a real curve from the five-term shape: it reduced the KVH 1750 X curve to white rate noise
// alone, which leaves the published band at four taus.)
class Evidence {
 public:
  // `rho`: the correlation of the points (avar_correlation.h).
  Evidence(const SubsetFits& fits, Eigen::Index n, Eigen::MatrixXd rho)
      : fits_(fits), n_(n), rho_(std::move(rho)) {}

  // Residual variance factor of a model: max(1, chi2 / dof).
  double Scale(unsigned mask) const {
    const Eigen::Index dof = n_ - Size(mask);
    return dof > 0 ? std::max(1.0, fits_[mask].chi2 / static_cast<double>(dof)) : 1.0;
  }

  // Covariance of ln c of the model's active terms: the sandwich, widened by Scale; `naive` gets
  // (J'J)^-1. The columns of the Jacobian are equilibrated first: a term drifting to its bound of
  // zero has a vanishing column, and neither the sandwich nor the design effect depends on the
  // scale of a parameter. A column that is exactly zero (a coefficient that underflowed) is left
  // out.
  Eigen::MatrixXd Covariance(unsigned mask, Eigen::MatrixXd* naive = nullptr) const;

  // Corrected rise of the misfit from `larger` to `larger` without term j (chi-square units with
  // 1 degree of freedom under the smaller model); NaN if either model could not be fitted.
  double Rise(unsigned larger, int j) const;

 private:
  const SubsetFits& fits_;
  Eigen::Index n_;
  Eigen::MatrixXd rho_;
};

// The best-fitting model of the largest size the points allow (all five terms from five points).
unsigned LargestModel(const SubsetFits& fits);

// The selected model (a mask of terms): terms removed from LargestModel by nested tests, steepest
// first (noise_model_selection.cc says why).
unsigned SelectModel(const SubsetFits& fits, const Eigen::MatrixXd& columns, double min_share,
                     double critical, const Evidence& evidence);

}  // namespace gyrodrift::allan::internal
