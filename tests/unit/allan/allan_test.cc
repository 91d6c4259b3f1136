#include "gyrodrift/allan/allan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "unit/allan/white_noise.h"

namespace gyrodrift::allan {
namespace {

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

TEST(AllanCompute, HandedOverSamplesGiveTheSameBits) {
  // The phase built in the samples' own storage (rate data: grown by one point) is the phase
  // built beside them; every field of every point is the same.
  const Eigen::VectorXd y = WhiteNoise(5001, 2.0, 21).array() + 3.0;
  for (DataType type : {DataType::kRate, DataType::kAngle}) {
    for (Deviation dev : {Deviation::kOadev, Deviation::kMdev, Deviation::kTotdev}) {
      const AllanOptions o{.rate_hz = 10.0, .data_type = type, .deviation = dev};
      const AllanResult kept = Compute(y, o);
      Eigen::VectorXd copy = y;
      const AllanResult handed = Compute(std::move(copy), o);
      EXPECT_EQ(handed.n_phase, kept.n_phase);
      ASSERT_EQ(handed.points.size(), kept.points.size());
      for (size_t i = 0; i < kept.points.size(); ++i) {
        const AllanPoint& a = kept.points[i];
        const AllanPoint& b = handed.points[i];
        EXPECT_EQ(b.dev, a.dev);
        EXPECT_EQ(b.edf, a.edf);
        EXPECT_EQ(b.dev_lo, a.dev_lo);
        EXPECT_EQ(b.alpha, a.alpha);
      }
    }
  }
  Eigen::VectorXd bad = y;
  bad[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Compute(std::move(bad), AllanOptions{}), DataError);
}


// ComputeWithGaps: the overlapping estimators over the cluster pairs of logged samples only.
namespace gaps {

// y = 1 3 2 _ 5 1 4 at 1 Hz, the fourth sample missing (NaN: never read).
Eigen::VectorXd HandRecord() {
  Eigen::VectorXd y(7);
  y << 1, 3, 2, std::numeric_limits<double>::quiet_NaN(), 5, 1, 4;
  return y;
}
const std::vector<bool> kHandLogged{true, true, true, false, true, true, true};

TEST(AllanGaps, OverlappingAdevSkipsThePairsThatHoldAMissingSample) {
  const AllanResult r = ComputeWithGaps(HandRecord(), kHandLogged, {});
  // m = 1: pairs (1,3) (3,2) (5,1) (1,4), differences 2 -1 -4 3: AVAR = 30 / (2 * 4). m = 2 needs
  // four logged samples in a row and has none: left out.
  ASSERT_EQ(r.points.size(), 1U);
  EXPECT_EQ(r.points[0].m, 1);
  EXPECT_EQ(r.points[0].n_terms, 4);
  EXPECT_NEAR(r.points[0].dev, std::sqrt(30.0 / 8.0), 1e-12);
  EXPECT_TRUE(r.points[0].dev_lo < r.points[0].dev && r.points[0].dev < r.points[0].dev_hi);
  // Overlapping Hadamard: triples (1,3,2) and (5,1,4), second differences -3 and 7.
  const AllanResult h = ComputeWithGaps(HandRecord(), kHandLogged, {.deviation = Deviation::kOhdev});
  ASSERT_EQ(h.points.size(), 1U);
  EXPECT_EQ(h.points[0].n_terms, 2);
  EXPECT_NEAR(h.points[0].dev, std::sqrt(58.0 / 12.0), 1e-12);
}

TEST(AllanGaps, EveryFlagSetIsComputeAndALongGapOnlyLosesTerms) {
  const Eigen::VectorXd y = WhiteNoise(2000, 1.0, 3);
  const AllanResult plain = Compute(y, {});
  const AllanResult masked = ComputeWithGaps(y, std::vector<bool>(2000, true), {});
  ASSERT_EQ(plain.points.size(), masked.points.size());
  for (size_t k = 0; k < plain.points.size(); ++k) {
    EXPECT_NEAR(masked.points[k].dev, plain.points[k].dev, 1e-12 * plain.points[k].dev);
    EXPECT_EQ(masked.points[k].n_terms, plain.points[k].n_terms);
    EXPECT_EQ(masked.points[k].alpha, plain.points[k].alpha);
    EXPECT_NEAR(masked.points[k].edf, plain.points[k].edf, 1e-9 * plain.points[k].edf);
  }
  // The samples 800..1199 missing: the estimate is that of the two runs pooled, whatever the
  // filled values were (here garbage).
  Eigen::VectorXd holed = y;
  std::vector<bool> logged(2000, true);
  for (int i = 800; i < 1200; ++i) {
    holed[i] = 1e6;
    logged[static_cast<size_t>(i)] = false;
  }
  const AllanResult r = ComputeWithGaps(holed, logged, {.grid = TauGrid::kList, .tau_list_s = {4.0}});
  double sum = 0.0;
  std::int64_t terms = 0;
  for (const auto& [begin, end] : {std::pair{0, 800}, std::pair{1200, 2000}}) {
    for (int i = begin; i + 8 <= end; ++i) {
      const double d = y.segment(i + 4, 4).sum() - y.segment(i, 4).sum();
      sum += d * d;
      ++terms;
    }
  }
  ASSERT_EQ(r.points.size(), 1U);
  EXPECT_EQ(r.points[0].n_terms, terms);
  EXPECT_NEAR(r.points[0].dev, std::sqrt(sum / (2.0 * static_cast<double>(terms) * 16.0)),
              1e-12);
  // A white-noise record keeps its level: within 10 % of the gap-free one at the short taus.
  const AllanResult gapped = ComputeWithGaps(holed, logged, {});
  for (const AllanPoint& p : gapped.points) {
    for (const AllanPoint& q : plain.points) {
      if (q.m == p.m && p.m <= 16) {
        EXPECT_NEAR(p.dev / q.dev, 1.0, 0.1) << "m = " << p.m;
      }
    }
  }
}

TEST(AllanGaps, RefusesWhatItCannotDoHonestly) {
  EXPECT_THROW(ComputeWithGaps(HandRecord(), kHandLogged, {.deviation = Deviation::kAdev}),
               UsageError);
  EXPECT_THROW(ComputeWithGaps(HandRecord(), kHandLogged, {.data_type = DataType::kAngle}),
               UsageError);
  EXPECT_THROW(ComputeWithGaps(HandRecord(), {true, false}, {}), DataError);
  try {
    ComputeWithGaps(HandRecord(), kHandLogged, {.grid = TauGrid::kList, .tau_list_s = {2.0}});
    ADD_FAILURE() << "a tau without a term was computed";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("needs 4 logged samples in a row, the longest run is 3"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace gaps
}  // namespace
}  // namespace gyrodrift::allan
