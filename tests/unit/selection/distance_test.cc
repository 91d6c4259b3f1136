// PDF distances against closed forms for two unit-variance Gaussians, symmetry, zero for
// identical densities, bounds for disjoint ones.
#include "gyrodrift/selection/distance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "gyrodrift/common/error.h"

namespace gyrodrift::selection {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr PdfDistance kAll[] = {PdfDistance::kL2, PdfDistance::kL1, PdfDistance::kHellinger,
                                PdfDistance::kJensenShannon, PdfDistance::kBhattacharyya};

struct Sampled {
  Eigen::VectorXd p, q;
  double step;
};

// N(0, 1) and N(mu, sigma^2) on [-15, 15].
Sampled Gaussians(double mu, double sigma, int points = 4001) {
  Sampled s;
  s.step = 30.0 / (points - 1);
  s.p.resize(points);
  s.q.resize(points);
  for (int j = 0; j < points; ++j) {
    const double g = -15.0 + j * s.step;
    s.p[j] = std::exp(-0.5 * g * g) / std::sqrt(2 * kPi);
    const double u = (g - mu) / sigma;
    s.q[j] = std::exp(-0.5 * u * u) / (std::sqrt(2 * kPi) * sigma);
  }
  return s;
}

TEST(PdfDistance, ClosedFormsForShiftedGaussians) {
  for (double mu : {0.3, 1.0, 2.5}) {
    const Sampled s = Gaussians(mu, 1.0);
    const double l2 = std::sqrt(2.0 / (2.0 * std::sqrt(kPi)) * (1.0 - std::exp(-mu * mu / 4.0)));
    const double l1 = 2.0 * std::erf(mu / (2.0 * std::sqrt(2.0)));
    const double hellinger = std::sqrt(1.0 - std::exp(-mu * mu / 8.0));
    const double bhattacharyya = mu * mu / 8.0;
    EXPECT_NEAR(Distance(PdfDistance::kL2, s.p, s.q, s.step), l2, 1e-9) << mu;
    EXPECT_NEAR(Distance(PdfDistance::kL1, s.p, s.q, s.step), l1, 1e-5) << mu;
    EXPECT_NEAR(Distance(PdfDistance::kHellinger, s.p, s.q, s.step), hellinger, 1e-9) << mu;
    EXPECT_NEAR(Distance(PdfDistance::kBhattacharyya, s.p, s.q, s.step), bhattacharyya, 1e-9);
    const double js = Distance(PdfDistance::kJensenShannon, s.p, s.q, s.step);
    EXPECT_GT(js, 0.0);
    EXPECT_LT(js, std::log(2.0));
  }
}

TEST(PdfDistance, SymmetricAndZeroForIdentical) {
  const Sampled s = Gaussians(0.7, 1.8);
  for (PdfDistance d : kAll) {
    const double pq = Distance(d, s.p, s.q, s.step);
    const double qp = Distance(d, s.q, s.p, s.step);
    EXPECT_GT(pq, 1e-3) << ToString(d);
    EXPECT_NEAR(pq, qp, 1e-14 * pq) << ToString(d);
    EXPECT_LE(Distance(d, s.p, s.p, s.step), 1e-12) << ToString(d);
    EXPECT_GE(Distance(d, s.p, s.p, s.step), 0.0) << ToString(d);
  }
}

TEST(PdfDistance, DisjointDensitiesReachTheBounds) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(100), q = Eigen::VectorXd::Zero(100);
  p.segment(0, 10).setConstant(0.1);
  q.segment(50, 10).setConstant(0.1);
  EXPECT_NEAR(Distance(PdfDistance::kL1, p, q, 1.0), 2.0, 1e-15);
  EXPECT_NEAR(Distance(PdfDistance::kHellinger, p, q, 1.0), 1.0, 1e-15);
  EXPECT_NEAR(Distance(PdfDistance::kJensenShannon, p, q, 1.0), std::log(2.0), 1e-15);
  EXPECT_NEAR(Distance(PdfDistance::kBhattacharyya, p, q, 1.0), -std::log(1e-300), 1e-9);
  EXPECT_NEAR(Distance(PdfDistance::kL2, p, q, 1.0), std::sqrt(0.2), 1e-15);
}

TEST(PdfDistance, NamesRoundTrip) {
  for (PdfDistance d : kAll) EXPECT_EQ(PdfDistanceFromString(ToString(d)), d);
  EXPECT_THROW(PdfDistanceFromString("kl"), UsageError);
}

}  // namespace
}  // namespace gyrodrift::selection
