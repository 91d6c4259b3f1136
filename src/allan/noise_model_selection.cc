// Which IEEE 952 terms the noise fit keeps (noise_model_selection.h).
#include "allan/noise_model_selection.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace gyrodrift::allan::internal {
namespace {

// Does term j carry at least `share` of the fitted model variance at some tau?
bool Carries(const SubsetFit& fit, int j, const Eigen::MatrixXd& columns, double share) {
  for (Eigen::Index r = 0; r < columns.rows(); ++r) {
    double model = 0.0;
    for (int k = 0; k < kTerms; ++k) model += fit.coef[static_cast<size_t>(k)] * columns(r, k);
    if (fit.coef[static_cast<size_t>(j)] * columns(r, j) >= share * model) return true;
  }
  return false;
}

}  // namespace

Eigen::MatrixXd Evidence::Covariance(unsigned mask, Eigen::MatrixXd* naive) const {
  const Eigen::MatrixXd& jacobian = fits_[mask].jacobian;
  const Eigen::Index k = jacobian.cols();
  std::vector<Eigen::Index> live;
  for (Eigen::Index c = 0; c < k; ++c)
    if (jacobian.col(c).norm() > 0.0) live.push_back(c);
  const auto l = static_cast<Eigen::Index>(live.size());
  Eigen::MatrixXd scaled(jacobian.rows(), l);
  Eigen::VectorXd norm(l);
  for (Eigen::Index c = 0; c < l; ++c) {
    norm[c] = jacobian.col(live[static_cast<size_t>(c)]).norm();
    scaled.col(c) = jacobian.col(live[static_cast<size_t>(c)]) / norm[c];
  }
  const Eigen::MatrixXd bread =
      (scaled.transpose() * scaled).ldlt().solve(Eigen::MatrixXd::Identity(l, l));
  const Eigen::MatrixXd sandwich =
      Scale(mask) * bread * (scaled.transpose() * rho_ * scaled) * bread;
  Eigen::MatrixXd robust = Eigen::MatrixXd::Zero(k, k);
  if (naive) *naive = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index i = 0; i < l; ++i) {
    for (Eigen::Index j = 0; j < l; ++j) {
      const auto a = live[static_cast<size_t>(i)], b = live[static_cast<size_t>(j)];
      robust(a, b) = sandwich(i, j) / (norm[i] * norm[j]);
      if (naive) (*naive)(a, b) = bread(i, j) / (norm[i] * norm[j]);
    }
  }
  return robust;
}

double Evidence::Rise(unsigned larger, int j) const {
  const unsigned smaller = larger & ~(1u << j);
  if (!fits_[smaller].ok || !fits_[larger].ok) return std::numeric_limits<double>::quiet_NaN();
  const double rise = std::max(0.0, fits_[smaller].chi2 - fits_[larger].chi2);
  const std::vector<int> active = TermsOf(larger);
  const auto c =
      static_cast<Eigen::Index>(std::find(active.begin(), active.end(), j) - active.begin());
  Eigen::MatrixXd naive;
  const Eigen::MatrixXd robust = Covariance(larger, &naive);
  double effect = robust(c, c) / naive(c, c);  // includes Scale(larger)
  if (!(effect > 0.0) || !std::isfinite(effect)) effect = Scale(larger);
  return rise / effect;
}

unsigned LargestModel(const SubsetFits& fits) {
  unsigned largest = 0;
  for (unsigned m = 1; m <= kAllTerms; ++m) {
    if (!fits[m].ok) continue;
    if (largest == 0 || Size(m) > Size(largest) ||
        (Size(m) == Size(largest) && fits[m].chi2 < fits[largest].chi2))
      largest = m;
  }
  return largest;
}

// Model selection by nested tests in the order of the IEEE 952 hierarchy. The model is a
// polynomial in tau and 1/tau, c_Q 3/tau^2 + c_N/tau + c_B 2ln2/pi + c_K tau/3 + c_R tau^2/2; as
// in polynomial regression, the steepest terms are tested for removal first: R and Q (tau^+-2),
// then K and N (tau^+-1), the flat bias-instability floor B last. From the largest model the
// points allow, the first term in that order that never carries min_share of the model, or whose
// removal raises the corrected misfit by less than `critical`, is removed, and the tests start
// again on the smaller model.
// Why an order: neighbouring terms overlap. Over the last octaves of a record a rising K and a
// flat B explain the same excess over the white rate noise, and which fits a little better is
// decided by the scatter of the last, least certain points. Keeping the best-fitting model of each
// size, or removing the least significant term first (the rule before this one), reports a rate
// random walk in about a quarter of 8-hour records of a navigation FOG whose K cannot show in 8
// hours (docs/allan.md); tested steepest first, a rise is claimed only where the curve rises
// significantly above a floor.
unsigned SelectModel(const SubsetFits& fits, const Eigen::MatrixXd& columns, double min_share,
                     double critical, const Evidence& evidence) {
  constexpr std::array<int, kTerms> kRemovalOrder{4, 0, 3, 1, 2};  // R, Q, K, N, B
  unsigned mask = LargestModel(fits);
  auto removable = [&](int j) {
    return (mask & (1u << j)) && Size(mask) > 1 && fits[mask & ~(1u << j)].ok;
  };
  while (mask != 0) {
    int remove = -1;
    for (const int j : kRemovalOrder) {
      if (removable(j) &&
          (!Carries(fits[mask], j, columns, min_share) || !(evidence.Rise(mask, j) >= critical))) {
        remove = j;
        break;
      }
    }
    if (remove < 0) break;
    mask &= ~(1u << remove);
  }
  return mask;
}

}  // namespace gyrodrift::allan::internal
