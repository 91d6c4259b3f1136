#include "gyrodrift/selection/distance.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"

namespace gyrodrift::selection {

namespace {

// a * ln(a / b) with the limits 0 ln 0 = 0; b >= a / 2 > 0 whenever a > 0 (b is the mixture).
double KlTerm(double a, double b) { return a > 0.0 ? a * std::log(a / b) : 0.0; }

constexpr gyrodrift::internal::EnumNames<PdfDistance, 5> kDistances{{
    {PdfDistance::kL2, "l2"},
    {PdfDistance::kL1, "l1"},
    {PdfDistance::kHellinger, "hellinger"},
    {PdfDistance::kJensenShannon, "jensen-shannon"},
    {PdfDistance::kBhattacharyya, "bhattacharyya"},
}};

}  // namespace

std::string_view ToString(PdfDistance distance) {
  return gyrodrift::internal::EnumName(distance, kDistances);
}

PdfDistance PdfDistanceFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "distance", kDistances);
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
