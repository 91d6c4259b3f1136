#include "gyrodrift/selection/distance.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "gyrodrift/common/check.h"

namespace gyrodrift::selection {

namespace {

// a * ln(a / b) with the limits 0 ln 0 = 0; b >= a / 2 > 0 whenever a > 0 (b is the mixture).
double KlTerm(double a, double b) { return a > 0.0 ? a * std::log(a / b) : 0.0; }

}  // namespace

std::string_view ToString(PdfDistance distance) {
  switch (distance) {
    case PdfDistance::kL2:
      return "l2";
    case PdfDistance::kL1:
      return "l1";
    case PdfDistance::kHellinger:
      return "hellinger";
    case PdfDistance::kJensenShannon:
      return "jensen-shannon";
    case PdfDistance::kBhattacharyya:
      return "bhattacharyya";
  }
  return "unknown";
}

PdfDistance PdfDistanceFromString(std::string_view name) {
  if (name == "l2") return PdfDistance::kL2;
  if (name == "l1") return PdfDistance::kL1;
  if (name == "hellinger") return PdfDistance::kHellinger;
  if (name == "jensen-shannon") return PdfDistance::kJensenShannon;
  if (name == "bhattacharyya") return PdfDistance::kBhattacharyya;
  ThrowOption("distance", "'" + std::string(name) + "'",
              "one of l2, l1, hellinger, jensen-shannon, bhattacharyya");
}

double Distance(PdfDistance distance, const Eigen::Ref<const Eigen::VectorXd>& p,
                const Eigen::Ref<const Eigen::VectorXd>& q, double step) {
  const Eigen::Index n = p.size();
  double sum = 0.0;
  switch (distance) {
    case PdfDistance::kL2:
      for (Eigen::Index j = 0; j < n; ++j) {
        const double d = std::max(0.0, p[j]) - std::max(0.0, q[j]);
        sum += d * d;
      }
      return std::sqrt(sum * step);
    case PdfDistance::kL1:
      for (Eigen::Index j = 0; j < n; ++j)
        sum += std::abs(std::max(0.0, p[j]) - std::max(0.0, q[j]));
      return sum * step;
    case PdfDistance::kHellinger:
      for (Eigen::Index j = 0; j < n; ++j) {
        const double d = std::sqrt(std::max(0.0, p[j])) - std::sqrt(std::max(0.0, q[j]));
        sum += d * d;
      }
      return std::sqrt(0.5 * sum * step);
    case PdfDistance::kJensenShannon:
      for (Eigen::Index j = 0; j < n; ++j) {
        const double a = std::max(0.0, p[j]);
        const double b = std::max(0.0, q[j]);
        const double m = 0.5 * (a + b);
        sum += KlTerm(a, m) + KlTerm(b, m);
      }
      // Each KL term is >= 0 in exact arithmetic; round-off must not make the divergence negative.
      return std::max(0.0, 0.5 * sum * step);
    case PdfDistance::kBhattacharyya:
      for (Eigen::Index j = 0; j < n; ++j)
        sum += std::sqrt(std::max(0.0, p[j]) * std::max(0.0, q[j]));
      // BC slightly above 1 from the Riemann sum of two identical densities gives a tiny negative
      // logarithm; the distance is 0 then.
      return std::max(0.0, -std::log(std::max(sum * step, 1e-300)));
  }
  return 0.0;
}

}  // namespace gyrodrift::selection
