// Equivalent degrees of freedom, chi-square quantiles and the lag-1 noise identification
// (gyrodrift/allan/edf.h): known table values, limits, and the power-law types of synthetic noise.
#include "gyrodrift/allan/edf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "unit/allan/white_noise.h"

namespace gyrodrift::allan {
namespace {

TEST(ChiSquare, QuantilesMatchKnownValues) {
  // Tables (Abramowitz & Stegun 26.4): chi2_{0.975}(1) = 5.0239, chi2_{0.05}(10) = 3.9403,
  // chi2_{0.5}(2) = 2 ln 2 exactly.
  EXPECT_NEAR(ChiSquareQuantile(0.975, 1.0), 5.02389, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.05, 10.0), 3.94030, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.5, 2.0), 2.0 * std::numbers::ln2, 1e-12);
  // dof = 2 is the exponential distribution: q = -2 ln(1 - p).
  for (double p : {0.001, 0.1585, 0.8415, 0.999})
    EXPECT_NEAR(ChiSquareQuantile(p, 2.0) / (-2.0 * std::log1p(-p)), 1.0, 1e-12) << p;
  // Inverse of P to machine precision at fractional dof.
  for (double dof : {0.7, 3.3, 47.0, 1999.0, 9999.0}) {
    for (double p : {0.01, 0.1585, 0.5, 0.8415, 0.99}) {
      const double q = ChiSquareQuantile(p, dof);
      EXPECT_NEAR(RegularizedGammaP(0.5 * dof, 0.5 * q), p, 1e-11) << dof << " " << p;
    }
  }
}

// Above 1e4 dof the quantile switches to Wilson-Hilferty: its relative error there, estimated by
// one Newton step (P(q) - p) / density(q), stays below 1e-6, far below the 1e-3 intervals need.
TEST(ChiSquare, WilsonHilfertyIsAccurateAboveSwitch) {
  for (double dof : {1.0001e4, 1e5, 1e6}) {
    for (double p : {0.01, 0.1585, 0.8415, 0.99}) {
      const double q = ChiSquareQuantile(p, dof);
      const double a = 0.5 * dof;
      const double density =
          0.5 * std::exp((a - 1.0) * std::log(0.5 * q) - 0.5 * q - std::lgamma(a));
      const double rel = (RegularizedGammaP(a, 0.5 * q) - p) / density / q;
      EXPECT_LT(std::abs(rel), 1e-6) << dof << " " << p;
    }
  }
}

TEST(Edf, TotdevTableAndGreenhallLimits) {
  // SP 1065 table 7: white FM, b = 1.5: edf = 1.5 (N-1)/m.
  EXPECT_DOUBLE_EQ(EquivalentDof(Deviation::kTotdev, 0, 10, 1001), 150.0);
  // OADEV white FM at m = 1 equals ADEV: both are the same estimator then.
  EXPECT_NEAR(EquivalentDof(Deviation::kOadev, 0, 1, 1001),
              EquivalentDof(Deviation::kAdev, 0, 1, 1001), 1e-9);
  // Overlapping never has fewer degrees of freedom than non-overlapping.
  for (int alpha : {2, 1, 0, -1, -2})
    for (std::int64_t m : {2, 8, 64})
      EXPECT_GE(EquivalentDof(Deviation::kOadev, alpha, m, 4001),
                EquivalentDof(Deviation::kAdev, alpha, m, 4001) * 0.999)
          << alpha << " " << m;
}

TEST(NoiseId, IdentifiesPowerLawTypes) {
  // White FM (alpha 0) on rate data, random-walk FM (alpha -2) from integrated white rate,
  // white PM (alpha 2) from white angle data.
  const Eigen::VectorXd w = WhiteNoise(20000, 1.0, 9);
  Eigen::VectorXd phase(w.size() + 1);
  phase[0] = 0;
  for (Eigen::Index i = 0; i < w.size(); ++i) phase[i + 1] = phase[i] + w[i];
  EXPECT_EQ(IdentifyAlpha(phase, 1, DataType::kRate, 2), 0);
  EXPECT_EQ(IdentifyAlpha(phase, 16, DataType::kRate, 2), 0);
  EXPECT_EQ(IdentifyAlpha(w, 1, DataType::kAngle, 2), 2);
  Eigen::VectorXd rw_phase(phase.size() + 1);
  rw_phase[0] = 0;
  for (Eigen::Index i = 0; i < phase.size(); ++i) rw_phase[i + 1] = rw_phase[i] + phase[i];
  EXPECT_EQ(IdentifyAlpha(rw_phase, 4, DataType::kRate, 2), -2);
  EXPECT_FALSE(IdentifyAlpha(phase, 1000, DataType::kRate, 2).has_value());  // < 30 points
}

}  // namespace
}  // namespace gyrodrift::allan
