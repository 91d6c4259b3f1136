// Correlation of overlapping Allan-variance estimates (avar_correlation.h).
#include "allan/avar_correlation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace gyrodrift::allan {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kPointsPerPanel = 1024;
constexpr double kFastPeriods = 32.0;  // oscillations per panel beyond which sin^4 is averaged

// Mean of sin^4(a x) sin^4(b x) over x for a <= b (see the header).
double MeanSin4Product(double a, double b) {
  const double ratio = b / a;
  if (std::abs(ratio - 1.0) < 1e-9) return 35.0 / 128.0;
  if (std::abs(ratio - 2.0) < 1e-9) return 7.0 / 64.0;
  return 9.0 / 64.0;
}

}  // namespace

Eigen::MatrixXd AvarCorrelation(const Eigen::VectorXd& m, const std::array<double, 5>& coef,
                                double tau0_s, const Eigen::VectorXd& n_terms) {
  const Eigen::Index t = m.size();
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(t, t);
  if (t == 0) return p;
  const double m_max = m.maxCoeff();
  std::vector<double> explicit_h(static_cast<size_t>(t)), envelope(static_cast<size_t>(t));
  std::vector<char> fast(static_cast<size_t>(t));
  for (double lo = 1.0 / (1024.0 * m_max); lo < 0.5; lo *= 2.0) {
    const double hi = std::min(2.0 * lo, 0.5);
    const double width = (hi - lo) / kPointsPerPanel;
    for (Eigen::Index i = 0; i < t; ++i) fast[static_cast<size_t>(i)] = m[i] * (hi - lo) > kFastPeriods;
    for (int k = 0; k < kPointsPerPanel; ++k) {
      const double f = lo + (k + 0.5) * width;
      const double s = std::sin(kPi * f);
      const double spectrum = coef[0] * 8.0 * s * s / (tau0_s * tau0_s) + coef[1] * 2.0 / tau0_s +
                              coef[2] / (kPi * f) + coef[3] * tau0_s / (2.0 * s * s);
      const double weight = width * spectrum * spectrum;
      for (Eigen::Index i = 0; i < t; ++i) {
        const auto u = static_cast<size_t>(i);
        envelope[u] = 4.0 / (m[i] * m[i] * s * s);
        if (!fast[u]) {
          const double a = std::sin(kPi * m[i] * f);
          explicit_h[u] = envelope[u] * a * a * a * a;
        }
      }
      for (Eigen::Index i = 0; i < t; ++i) {
        const auto u = static_cast<size_t>(i);
        for (Eigen::Index j = i; j < t; ++j) {
          const auto v = static_cast<size_t>(j);
          double product;
          if (fast[u] && fast[v]) {
            product = envelope[u] * envelope[v] * MeanSin4Product(std::min(m[i], m[j]),
                                                                  std::max(m[i], m[j]));
          } else if (fast[u]) {
            product = envelope[u] * 0.375 * explicit_h[v];
          } else if (fast[v]) {
            product = explicit_h[u] * envelope[v] * 0.375;
          } else {
            product = explicit_h[u] * explicit_h[v];
          }
          p(i, j) += weight * product;
        }
      }
    }
  }
  Eigen::MatrixXd rho = Eigen::MatrixXd::Identity(t, t);
  for (Eigen::Index i = 0; i < t; ++i) {
    for (Eigen::Index j = i + 1; j < t; ++j) {
      const double denominator = std::sqrt(p(i, i) * p(j, j));
      if (!(denominator > 0.0)) continue;
      double r = p(i, j) / denominator;
      if (n_terms.size() == t) {
        const double a = n_terms[i], b = n_terms[j];
        r *= std::sqrt(std::min(a, b) / std::max(a, b));
      }
      rho(i, j) = rho(j, i) = r;
    }
  }
  return rho;
}

}  // namespace gyrodrift::allan
