#include "gyrodrift/allan/allan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "allan/kernels.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::allan {
namespace {

Eigen::VectorXd WhiteNoise(Eigen::Index n, double sigma, std::uint64_t seed) {
  Rng rng(seed, 0);
  Eigen::VectorXd v(n);
  rng.FillNormal(v);
  return v * sigma;
}

TEST(AllanEnums, RoundTripAndReject) {
  for (auto d : {Deviation::kAdev, Deviation::kOadev, Deviation::kMdev, Deviation::kHdev,
                 Deviation::kOhdev, Deviation::kTdev, Deviation::kTotdev})
    EXPECT_EQ(DeviationFromString(ToString(d)), d);
  for (auto g : {TauGrid::kAll, TauGrid::kOctave, TauGrid::kDecade, TauGrid::kList})
    EXPECT_EQ(TauGridFromString(ToString(g)), g);
  for (auto u : {RateUnit::kDegPerHour, RateUnit::kDegPerSecond, RateUnit::kRadPerSecond})
    EXPECT_EQ(RateUnitFromString(ToString(u)), u);
  EXPECT_EQ(DataTypeFromString("angle"), DataType::kAngle);
  EXPECT_THROW(DeviationFromString("allan"), UsageError);
  EXPECT_THROW(RateUnitFromString("rpm"), UsageError);
}

TEST(AllanOptions, ValidateNamesTheField) {
  AllanOptions o;
  o.rate_hz = 0.0;
  try {
    o.Validate();
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("rate_hz = 0"), std::string::npos) << e.what();
  }
  o = {};
  o.confidence = 1.0;
  EXPECT_THROW(o.Validate(), UsageError);
  o = {};
  o.grid = TauGrid::kList;
  o.tau_list_s = {1.0, -2.0};
  EXPECT_THROW(o.Validate(), UsageError);
  o.tau_list_s = {};
  EXPECT_THROW(o.Validate(), UsageError);
  o = {};
  o.deviation = Deviation::kOadev;
  o.forced_alpha = -3;  // alpha + 2d must exceed 1
  EXPECT_THROW(o.Validate(), UsageError);
}

TEST(AllanCompute, RejectsNonFiniteAndShortData) {
  Eigen::VectorXd x = WhiteNoise(100, 1.0, 1);
  x[17] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Compute(x, {}), DataError);
  EXPECT_THROW(Compute(Eigen::VectorXd::Ones(1), {}), DataError);
  AllanOptions o{.grid = TauGrid::kList, .tau_list_s = {60.0}};
  EXPECT_THROW(Compute(WhiteNoise(100, 1.0, 1), o), DataError);  // m = 60 > (101 - 1) / 2
}

TEST(AllanGrid, OctaveDecadeAllAndListFactors) {
  AllanOptions o;
  o.grid = TauGrid::kOctave;
  EXPECT_EQ(AveragingFactors(o, 1001),
            (std::vector<std::int64_t>{1, 2, 4, 8, 16, 32, 64, 128, 256}));
  o.grid = TauGrid::kDecade;
  EXPECT_EQ(AveragingFactors(o, 1001),
            (std::vector<std::int64_t>{1, 2, 4, 10, 20, 40, 100, 200, 400}));
  o.grid = TauGrid::kAll;
  EXPECT_EQ(AveragingFactors(o, 11).size(), 5u);
  o.grid = TauGrid::kList;
  o.rate_hz = 10.0;
  o.tau_list_s = {0.04, 0.26, 0.3, 0.01};
  EXPECT_EQ(AveragingFactors(o, 1001), (std::vector<std::int64_t>{1, 3}));
  EXPECT_EQ(MaxAveragingFactor(Deviation::kMdev, 1001), 333);
  EXPECT_EQ(TermCount(Deviation::kAdev, 1001, 2), 499);
  EXPECT_EQ(TermCount(Deviation::kHdev, 1001, 2), 498);
}

// White rate noise of spectral density sigma^2 tau0: AVAR(tau) = sigma^2 tau0 / tau for every
// Allan-type estimator, MVAR = AVAR / m asymptotically (x (1 + ... ) for finite m), HVAR = AVAR.
TEST(AllanCompute, WhiteRateNoiseFollowsTheMinusHalfSlope) {
  const Eigen::VectorXd y = WhiteNoise(200000, 2.0, 7);
  for (auto d : {Deviation::kAdev, Deviation::kOadev, Deviation::kHdev, Deviation::kOhdev,
                 Deviation::kTotdev}) {
    AllanOptions o{.rate_hz = 4.0, .deviation = d, .grid = TauGrid::kOctave};
    const AllanResult r = Compute(y, o);
    for (const auto& p : r.points) {
      if (p.m > 256) break;
      const double expected = 2.0 * std::sqrt(0.25 / p.tau_s);
      EXPECT_NEAR(p.dev / expected, 1.0, 5.0 / std::sqrt(p.edf)) << ToString(d) << " m " << p.m;
      EXPECT_LE(p.dev_lo, p.dev);
      EXPECT_GE(p.dev_hi, p.dev);
      EXPECT_EQ(p.alpha, 0) << ToString(d) << " m " << p.m;  // noise ID: white FM
    }
  }
}

// Rate input and the matching angle input give the same deviations, with the unit scaling of
// deg/h (angle in degrees, tau in seconds).
TEST(AllanCompute, RateAndAngleInputsAgreeInEveryUnit) {
  const Eigen::VectorXd y = WhiteNoise(5000, 0.3, 3).array() + 12.5;
  for (auto unit : {RateUnit::kDegPerHour, RateUnit::kDegPerSecond, RateUnit::kRadPerSecond}) {
    const double rate_hz = 5.0;
    // angle in deg (rad for rad/s): integrate the rate, converting hours for deg/h
    const double per_s = unit == RateUnit::kDegPerHour ? 1.0 / 3600.0 : 1.0;
    Eigen::VectorXd angle(y.size() + 1);
    angle[0] = 0.0;
    for (Eigen::Index i = 0; i < y.size(); ++i) angle[i + 1] = angle[i] + y[i] * per_s / rate_hz;
    for (auto d : {Deviation::kOadev, Deviation::kMdev, Deviation::kTotdev}) {
      AllanOptions o{.rate_hz = rate_hz,
                     .data_type = DataType::kRate,
                     .deviation = d,
                     .units = unit,
                     .confidence_intervals = false};
      const AllanResult a = Compute(y, o);
      o.data_type = DataType::kAngle;
      const AllanResult b = Compute(angle, o);
      ASSERT_EQ(a.points.size(), b.points.size());
      for (size_t i = 0; i < a.points.size(); ++i)
        EXPECT_NEAR(a.points[i].dev / b.points[i].dev, 1.0, 1e-9) << ToString(unit) << " " << i;
    }
  }
}

TEST(AllanCompute, ResultsDoNotDependOnThreadCountOrGrouping) {
  const Eigen::VectorXd y = WhiteNoise(30000, 1.0, 11);
  const AllanOptions o{.grid = TauGrid::kAll};
  const AllanResult one = Compute(y, o, {.threads = 1});
  const AllanResult three = Compute(y, o, {.threads = 3});
  ASSERT_EQ(one.points.size(), three.points.size());
  for (size_t i = 0; i < one.points.size(); ++i) {
    EXPECT_EQ(one.points[i].dev, three.points[i].dev);
    EXPECT_EQ(one.points[i].dev_lo, three.points[i].dev_lo);
  }
  // The list grid computes factors in other groups; the blocked kernel must give the same bits.
  AllanOptions l{.grid = TauGrid::kList, .tau_list_s = {7.0, 100.0, 5000.0}};
  const AllanResult some = Compute(y, l);
  EXPECT_EQ(some.points[0].dev, one.points[6].dev);
  EXPECT_EQ(some.points[1].dev, one.points[99].dev);
  EXPECT_EQ(some.points[2].dev, one.points[4999].dev);
}

TEST(AllanKernels, BlockedSumsEqualDirectSums) {
  const Eigen::VectorXd x = WhiteNoise(10007, 1.0, 5);
  const std::vector<std::int64_t> ms = {1, 2, 3, 9, 40, 41, 200, 3000, 5003};
  std::vector<double> out(ms.size());
  internal::OverlappingSecondDifferenceSums(x.data(), x.size(), ms.data(),
                                            static_cast<int>(ms.size()), out.data());
  for (size_t k = 0; k < ms.size(); ++k) {
    const std::int64_t m = ms[k];
    long double ref = 0.0L;
    for (std::int64_t i = 0; i + 2 * m < x.size(); ++i) {
      const long double d = x[i + 2 * m] - 2.0L * x[i + m] + x[i];
      ref += d * d;
    }
    EXPECT_NEAR(out[k] / static_cast<double>(ref), 1.0, 1e-12) << m;
  }
}

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
