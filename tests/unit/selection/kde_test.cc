// Binned-FFT Gaussian KDE: mass, agreement with the exact O(n * grid) sum within the linear
// binning error bound, Silverman's bandwidth, grid refinement and input checks.
#include "gyrodrift/selection/kde.h"

#include <gtest/gtest.h>

#include <cmath>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::selection {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::VectorXd Normals(Eigen::Index n, std::uint64_t stream) {
  Eigen::VectorXd x(n);
  Rng(7, stream).FillNormal(x);
  return x;
}

// A skewed, bimodal sample: the density has structure at several scales.
Eigen::VectorXd Mixture(Eigen::Index n) {
  Eigen::VectorXd x = Normals(n, 1);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = (i % 3 == 0) ? 4.0 + 0.3 * x[i] : x[i];
  return x;
}

// Largest deviation of the binned estimate from the exact one allowed by linear binning:
// |(1 - t) K(a) + t K(a - d) - K(a - t d)| <= d^2 / 8 * max|K''| = d^2 / (8 sqrt(2 pi) h^3).
double BinningBound(double step, double h) {
  return step * step / (8.0 * std::sqrt(2.0 * kPi) * h * h * h);
}

TEST(Kde, IntegratesToOne) {
  for (Eigen::Index n : {50, 1000, 100000}) {
    const Kde kde = EstimateKde(Mixture(n));
    EXPECT_NEAR(kde.density.sum() * kde.grid.step, 1.0, 1e-6) << n;
    EXPECT_GE(kde.density.minCoeff(), 0.0);
    EXPECT_GE(kde.grid.points, 512);
  }
}

TEST(Kde, BinnedFftMatchesDirectWithinBinningBound) {
  const Eigen::VectorXd x = Mixture(3000);
  for (int points : {64, 512, 2048}) {
    KdeOptions options{.grid_points = points, .points_per_bandwidth = 0.0};
    const Kde binned = EstimateKde(x, options);
    options.method = KdeMethod::kDirect;
    const Kde direct = EstimateKde(x, options);
    ASSERT_EQ(binned.grid.points, points);
    ASSERT_EQ(direct.grid.points, points);
    const double bound =
        BinningBound(binned.grid.step, binned.bandwidth) + 1e-13 * direct.density.maxCoeff();
    const double err = (binned.density - direct.density).cwiseAbs().maxCoeff();
    EXPECT_LE(err, bound) << points;
    // The bound is not vacuous: the coarse grid shows a real binning error of its order.
    if (points == 64) {
      EXPECT_GT(err, 0.01 * bound);
    }
  }
}

TEST(Kde, AffineImageMatchesTransformedSample) {
  const Eigen::VectorXd x = Mixture(2000);
  const double shift = 3.5, scale = 2.25;
  const Eigen::VectorXd y = (x.array() - shift) / scale;
  const double h = SilvermanBandwidth(y);
  EXPECT_NEAR(SilvermanBandwidth(x) / scale, h, 1e-14);
  const Grid grid = MakeGrid(y.minCoeff() - 5 * h, y.maxCoeff() + 5 * h, h, KdeOptions{});
  KdeWorkspace workspace;
  Eigen::VectorXd a(grid.points), b(grid.points);
  EstimateDensity(x, shift, scale, h, grid, KdeMethod::kDirect, &workspace, a);
  EstimateDensity(y, 0.0, 1.0, h, grid, KdeMethod::kDirect, &workspace, b);
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-12 * b.maxCoeff());
}

TEST(Kde, MatchesTheSmoothedTrueDensity) {
  // E[KDE] of a N(0,1) sample is the N(0, 1 + h^2) density; the pointwise standard deviation is
  // at most sqrt(f(0) R(K) / (n h)) with R(K) = 1 / (2 sqrt(pi)): allow 4.5 of them (512 points).
  const Eigen::Index n = 100000;
  const Kde kde = EstimateKde(Normals(n, 2));
  const double sd_max =
      std::sqrt(1.0 / std::sqrt(2.0 * kPi) / (2.0 * std::sqrt(kPi)) / (n * kde.bandwidth));
  const double s = std::sqrt(1.0 + kde.bandwidth * kde.bandwidth);
  double worst = 0.0;
  for (int j = 0; j < kde.grid.points; ++j) {
    const double u = kde.grid.At(j) / s;
    const double truth = std::exp(-0.5 * u * u) / (std::sqrt(2.0 * kPi) * s);
    worst = std::max(worst, std::abs(kde.density[j] - truth));
  }
  EXPECT_LT(worst, 4.5 * sd_max);
  EXPECT_GT(worst, 0.5 * sd_max);  // sampling noise is there: the estimate is not the truth
}

TEST(Kde, SilvermanBandwidthByHand) {
  Eigen::VectorXd x(10);
  for (int i = 0; i < 10; ++i) x[i] = i + 1.0;
  // sd = sqrt(110 / 12) = 3.0277; quartiles (type 7) 3.25 and 7.75, IQR / 1.34 = 3.358 > sd.
  const double sd = std::sqrt(110.0 / 12.0);
  EXPECT_NEAR(SilvermanBandwidth(x), 0.9 * sd * std::pow(10.0, -0.2), 1e-14);
  // Heavy outliers: the IQR branch takes over.
  x[9] = 1000.0;
  const double iqr = (7.75 - 3.25) / 1.34;
  EXPECT_NEAR(SilvermanBandwidth(x), 0.9 * iqr * std::pow(10.0, -0.2), 1e-14);
  EXPECT_EQ(SilvermanBandwidth(Eigen::VectorXd::Constant(20, 2.0)), 0.0);
}

TEST(Kde, GridRefinesForNarrowDensitiesAndFlagsTheCap) {
  const KdeOptions options;
  const Grid wide = MakeGrid(-10.0, 10.0, 1.0, options);
  EXPECT_EQ(wide.points, 512);
  EXPECT_FALSE(wide.under_resolved);
  const Grid fine = MakeGrid(-10.0, 10.0, 0.01, options);
  EXPECT_LE(fine.step, 0.01 / options.points_per_bandwidth * (1 + 1e-12));
  EXPECT_FALSE(fine.under_resolved);
  const Grid capped = MakeGrid(-10.0, 10.0, 1e-6, options);
  EXPECT_EQ(capped.points, options.max_grid_points);
  EXPECT_TRUE(capped.under_resolved);
  EXPECT_DOUBLE_EQ(capped.hi(), 10.0);
}

TEST(Kde, WorkspaceReuseGivesIdenticalBits) {
  const Eigen::VectorXd x = Mixture(5000);
  const Eigen::VectorXd y = Normals(300, 3);
  const Kde a = EstimateKde(x);
  KdeWorkspace workspace;
  Eigen::VectorXd first(a.grid.points), again(a.grid.points), other(a.grid.points);
  EstimateDensity(x, 0.0, 1.0, a.bandwidth, a.grid, KdeMethod::kBinnedFft, &workspace, first);
  EstimateDensity(y, 0.0, 1.0, 0.3, a.grid, KdeMethod::kBinnedFft, &workspace, other);
  EstimateDensity(x, 0.0, 1.0, a.bandwidth, a.grid, KdeMethod::kBinnedFft, &workspace, again);
  EXPECT_EQ(first, a.density);
  EXPECT_EQ(again, a.density);
}

TEST(Kde, RejectsBadInputAndOptions) {
  Eigen::VectorXd x = Normals(100, 4);
  EXPECT_THROW(EstimateKde(x, KdeOptions{.grid_points = 15}), UsageError);
  EXPECT_THROW(EstimateKde(x, KdeOptions{.grid_points = 512, .max_grid_points = 100}), UsageError);
  EXPECT_THROW(EstimateKde(x, KdeOptions{.bandwidth_scale = 0.0}), UsageError);
  EXPECT_THROW(EstimateKde(x, KdeOptions{.points_per_bandwidth = -1.0}), UsageError);
  EXPECT_THROW(EstimateKde(Eigen::VectorXd::Constant(50, 1.0)), DataError);
  EXPECT_THROW(EstimateKde(Eigen::VectorXd(1)), DataError);
  x[17] = std::nan("");
  EXPECT_THROW(EstimateKde(x), DataError);
  try {
    EstimateKde(Normals(100, 4), KdeOptions{.grid_points = 8});
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("grid_points = 8"), std::string::npos) << e.what();
  }
}

TEST(Kde, MethodNamesRoundTrip) {
  for (KdeMethod m : {KdeMethod::kBinnedFft, KdeMethod::kDirect}) {
    EXPECT_EQ(KdeMethodFromString(ToString(m)), m);
  }
  EXPECT_THROW(KdeMethodFromString("fft"), UsageError);
}

}  // namespace
}  // namespace gyrodrift::selection
