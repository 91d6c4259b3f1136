#include "gyrodrift/simulation/winding.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/simulation/gyro_noise.h"

namespace gyrodrift::simulation {
namespace {

const WindingPattern kAllPatterns[] = {WindingPattern::kQuadrupole, WindingPattern::kDipole,
                                       WindingPattern::kOctupole, WindingPattern::kConventional,
                                       WindingPattern::kSymmetric};

Eigen::VectorXd RadiusCapacity(int layers) {
  Eigen::VectorXd c(layers);
  for (int l = 0; l < layers; ++l) c[l] = 0.046 + (l + 0.5) * 2.5e-4;
  return c;
}

TEST(Winding, EveryPatternLaysTheWholeFibreExactlyOnce) {
  for (const auto pattern : kAllPatterns) {
    for (const double asymmetry : {0.0, 0.01}) {
      const WindingMap map = BuildWinding(pattern, 32, 1000.0, asymmetry, RadiusCapacity(32));
      std::vector<std::pair<double, double>> all;
      for (const auto& layer : map.pieces) all.insert(all.end(), layer.begin(), layer.end());
      std::sort(all.begin(), all.end());
      ASSERT_DOUBLE_EQ(all.front().first, 0.0) << ToString(pattern);
      ASSERT_DOUBLE_EQ(all.back().second, 1000.0) << ToString(pattern);
      for (size_t i = 1; i < all.size(); ++i) {
        ASSERT_NEAR(all[i].first, all[i - 1].second, 1e-9)
            << ToString(pattern);  // no gap, no overlap
        ASSERT_LT(all[i].first, all[i].second);
      }
      EXPECT_NEAR(map.layer_length_m.sum(), 1000.0, 1e-9);
      // Uniform heating rate: integral_0^L (L - 2z) dz = 0 for any winding.
      EXPECT_NEAR(ShupeIntegral(map, Eigen::VectorXd::Constant(32, 1e-3)), 0.0, 1e-9)
          << ToString(pattern);
      EXPECT_EQ(ShupeIntegral(map, Eigen::VectorXd::Zero(32)), 0.0);
    }
  }
}

TEST(Winding, QuadrupoleStartsAtTheMidpointWithAbbaLayers) {
  const WindingMap map = BuildWinding(WindingPattern::kQuadrupole, 8, 800.0, 0.0);
  // Equal capacities: 100 m per layer. Layer 0 (A) holds 300..400, layer 1 (B) 400..500,
  // layer 2 (B) 500..600, layer 3 (A) 200..300.
  EXPECT_EQ(map.LayerAt(350.0), 0);
  EXPECT_EQ(map.LayerAt(450.0), 1);
  EXPECT_EQ(map.LayerAt(550.0), 2);
  EXPECT_EQ(map.LayerAt(250.0), 3);
  EXPECT_EQ(map.LayerAt(50.0), 7);
  EXPECT_EQ(map.LayerAt(750.0), 6);
  EXPECT_THROW(map.LayerAt(900.0), UsageError);
  // Asymmetry moves the midpoint.
  const WindingMap shifted = BuildWinding(WindingPattern::kQuadrupole, 8, 800.0, 0.01);
  EXPECT_DOUBLE_EQ(shifted.pieces[0][0].second, 404.0);
  EXPECT_DOUBLE_EQ(shifted.pieces[1][0].first, 404.0);
}

TEST(Winding, PerfectlySymmetricWindingCancelsShupeToRoundOff) {
  Rng rng(7, StreamId("winding-test"));
  for (const int layers : {20, 32, 400}) {
    const WindingMap map =
        BuildWinding(WindingPattern::kSymmetric, layers, 1000.0, 0.0, RadiusCapacity(layers));
    Eigen::VectorXd rate(layers);
    for (int l = 0; l < layers; ++l) rate[l] = 1e-3 * rng.Normal();
    // Scale of one layer's contribution: L^2 / layers * |rate|; round-off is 1e-16 of the sum.
    const double scale = 1000.0 * 1000.0 * rate.cwiseAbs().sum();
    EXPECT_LT(std::abs(ShupeIntegral(map, rate)), 1e-14 * scale) << layers;
    EXPECT_LT(map.shupe_weight_m2.cwiseAbs().maxCoeff(), 1e-9);
  }
}

// Conventional coil, rate spread s along the fibre: dT/dt(z) = r0 + s z / L. Each layer sees the
// rate at its middle; the exact integral is -s L^2 / 6 and the midpoint rule errs by
// s L^2 / 6 / layers^2 (equal layers), so the sum converges to n L C s / (6 D).
double ConventionalShupe(int layers, const Eigen::VectorXd& capacity) {
  const ShupeConstants c;  // METHOD.md values
  const WindingMap map =
      BuildWinding(WindingPattern::kConventional, layers, c.fibre_length_m, 0.0, capacity);
  const double spread = 1e-3;
  Eigen::VectorXd rate(layers);
  for (int l = 0; l < layers; ++l) {
    const auto [a, b] = map.pieces[static_cast<size_t>(l)][0];
    rate[l] = 0.02 + spread * 0.5 * (a + b) / c.fibre_length_m;
  }
  return c.Scale() * ShupeIntegral(map, rate);
}

TEST(Winding, UnsymmetrisedCoilReproducesTheClosedForm) {
  const ShupeConstants c;
  const double closed = c.LinearSpreadClosedForm(1e-3);
  // n L C s / (6 D) with n = 1.468, C = 1e-5 + 1.468 * 5.5e-7, L = 1 km, D = 0.1 m: 5.45 deg/h.
  EXPECT_NEAR(closed * kDegPerHourPerRadPerSecond, 5.454, 0.001);
  EXPECT_NEAR(-ConventionalShupe(32, {}), closed, closed / (32.0 * 32.0) * 1.0001);
  EXPECT_NEAR(-ConventionalShupe(32, {}), closed * (1.0 - 1.0 / (32.0 * 32.0)), 1e-12 * closed);
  EXPECT_NEAR(-ConventionalShupe(2000, {}), closed, 1e-6 * closed);
  EXPECT_NEAR(-ConventionalShupe(32, RadiusCapacity(32)), closed, 2e-3 * closed);
}

TEST(Winding, QuadrupoleCancelsALinearRadialRateProfileFarBetterThanConventional) {
  const int layers = 32;
  Eigen::VectorXd rate(layers);
  for (int l = 0; l < layers; ++l) rate[l] = 1e-3 * l / (layers - 1.0);  // hub to outside
  const auto shupe = [&](WindingPattern p) {
    return std::abs(ShupeIntegral(BuildWinding(p, layers, 1000.0, 0.0), rate));
  };
  const double conventional = shupe(WindingPattern::kConventional);
  EXPECT_GT(conventional / shupe(WindingPattern::kDipole), 5.0);
  EXPECT_GT(conventional / shupe(WindingPattern::kQuadrupole), 50.0);
  EXPECT_GT(shupe(WindingPattern::kDipole), shupe(WindingPattern::kQuadrupole));
}

TEST(Winding, RejectsBadArguments) {
  EXPECT_THROW(BuildWinding(WindingPattern::kQuadrupole, 30, 1000.0, 0.0), UsageError);
  EXPECT_THROW(BuildWinding(WindingPattern::kQuadrupole, 32, -1.0, 0.0), UsageError);
  EXPECT_THROW(BuildWinding(WindingPattern::kQuadrupole, 32, 1000.0, 0.5), UsageError);
  EXPECT_THROW(BuildWinding(WindingPattern::kQuadrupole, 32, 1000.0, 0.0, Eigen::VectorXd::Ones(3)),
               UsageError);
  EXPECT_THROW(WindingPatternFromString("sextupole"), UsageError);
  EXPECT_EQ(WindingPatternFromString("helical"), WindingPattern::kConventional);
  for (const auto p : kAllPatterns) EXPECT_EQ(WindingPatternFromString(ToString(p)), p);
}

}  // namespace
}  // namespace gyrodrift::simulation
