// Thermal features and records (features.h): the first-order lags, ladder rungs and classic
// features of a temperature record, the time constants a training record keeps; joined rows of
// several records keep track of where each starts, starts are checked, and every record is
// visited once, in order.
#include "gyrodrift/drift/features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

TEST(ThermalFeatures, FirstOrderLagsAndTheirRates) {
  FeatureOptions o;
  o.thermal_set = ThermalSet::kLagBank;
  o.time_constants_s = {10.0};
  Eigen::VectorXd step = Eigen::VectorXd::Constant(200, 5.0);
  step.tail(100).setConstant(15.0);
  const Eigen::MatrixXd f = ThermalFeatures(step, o);
  ASSERT_EQ(f.cols(), 3);
  EXPECT_EQ(f(99, 1), 5.0);  // steady state: the lag equals the input, the rate is zero
  EXPECT_EQ(f(99, 2), 0.0);
  // Exact first-order step response: after k samples the lag has covered 1 - exp(-k dt / tau).
  EXPECT_NEAR(f(109, 1), 15.0 - 10.0 * std::exp(-10.0 / 10.0), 1e-12);
  EXPECT_NEAR(f(109, 2), (15.0 - f(109, 1)) / 10.0, 1e-15);
  // Causal: changing the future leaves every earlier row unchanged.
  Eigen::VectorXd changed = step;
  changed.tail(50).setConstant(-3.0);
  const Eigen::MatrixXd g = ThermalFeatures(changed, o);
  EXPECT_EQ(f.topRows(150), g.topRows(150));
}

TEST(ThermalFeatures, LadderRungsAddUpToTheTemperatureAndClassicIsTemperatureAndRate) {
  const Log log = MakeLog(2000, 11);
  FeatureOptions o;  // kAuto counts as the ladder here
  const Eigen::MatrixXd ladder = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(ladder.cols(), 7);
  EXPECT_EQ(o.NumThermalFeatures(), 7);
  // Rungs plus the slowest lag telescope back to T (to rounding).
  EXPECT_LE((ladder.leftCols(6).rowwise().sum() - log.temperature).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(ladder(100, 6), std::pow(log.temperature[100] - 20.0, 2), 1e-12);
  o.thermal_set = ThermalSet::kLagBank;
  const Eigen::MatrixXd bank = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(bank.cols(), 11);
  EXPECT_NEAR((ladder.col(0) - (log.temperature - bank.col(1))).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  o.thermal_set = ThermalSet::kClassic;
  const Eigen::MatrixXd classic = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(classic.cols(), 2);
  EXPECT_EQ(classic.col(0), log.temperature);
  EXPECT_EQ(classic.col(1), bank.col(2));  // (T - T_60) / 60, K/s
  // The drift model resolves auto: classic for poly, ladder for the rest.
  DriftOptions d;
  d.method = Method::kPoly;
  EXPECT_EQ(EffectiveFeatures(d).thermal_set, ThermalSet::kClassic);
  d.method = Method::kMsElm;
  EXPECT_EQ(EffectiveFeatures(d).thermal_set, ThermalSet::kLadder);
  EXPECT_EQ(ThermalSetFromString("lag-bank"), ThermalSet::kLagBank);
  EXPECT_THROW(ThermalSetFromString("cubic"), UsageError);
  o.time_constants_s.clear();
  EXPECT_THROW(o.Validate(), UsageError);  // classic needs a smoothing time constant
}

TEST(ThermalFeatures, RejectsBadInput) {
  FeatureOptions o;
  Eigen::VectorXd t = Eigen::VectorXd::Constant(10, 1.0);
  t[3] = std::nan("");
  EXPECT_THROW(ThermalFeatures(t, o), DataError);
  o.time_constants_s = {0.0};
  EXPECT_THROW(ThermalFeatures(Eigen::VectorXd::Ones(10), o), UsageError);
  o = FeatureOptions{};
  o.rate_hz = 0.0;
  EXPECT_THROW(o.Validate(), UsageError);
}

TEST(ThermalFeatures, TimeConstantsLongerThanAQuarterOfTheTrainingRecordAreDropped) {
  FeatureOptions o;  // 60, 300, 900, 1800, 3600 s at 1 Hz
  EXPECT_EQ(ForTrainingRecord(o, 28800).time_constants_s, o.time_constants_s);  // 8 h: all
  EXPECT_EQ(ForTrainingRecord(o, 7200).time_constants_s, (std::vector<double>{60, 300, 900, 1800}));
  EXPECT_EQ(ForTrainingRecord(o, 3000).time_constants_s, (std::vector<double>{60, 300}));
  EXPECT_EQ(ForTrainingRecord(o, 100).time_constants_s, (std::vector<double>{60}));  // shortest
  EXPECT_FALSE(ForTrainingRecord(o, 100).limit_time_constants);
  o.rate_hz = 0.1;  // 3000 samples are 30000 s
  EXPECT_EQ(ForTrainingRecord(o, 3000).time_constants_s, o.time_constants_s);
  o.rate_hz = 1.0;
  o.limit_time_constants = false;
  EXPECT_EQ(ForTrainingRecord(o, 100).time_constants_s, o.time_constants_s);
  // A fitted model keeps what it used, with the limit off, so a saved model estimates the same.
  const Log log = MakeLog(3000, 12);
  const DriftModel model =
      FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kPoly));
  EXPECT_EQ(model.options.features.time_constants_s, (std::vector<double>{60, 300}));
  EXPECT_FALSE(model.options.features.limit_time_constants);
}

TEST(Records, AppendedBlocksShiftTheirOwnStarts) {
  RecordRows run;
  run.Append(Eigen::MatrixXd::Constant(3, 2, 1.0));
  run.Append(Eigen::MatrixXd::Constant(5, 2, 2.0), {2});  // a block split at its row 2
  run.Append(Eigen::MatrixXd::Constant(1, 2, 3.0));
  EXPECT_EQ(run.rows.rows(), 9);
  EXPECT_EQ(run.record_starts, (std::vector<Eigen::Index>{3, 5, 8}));
  EXPECT_EQ(run.rows(4, 1), 2.0);
  EXPECT_EQ(run.rows(8, 0), 3.0);
  EXPECT_THROW(run.Append(Eigen::MatrixXd::Zero(2, 3)), DataError);

  std::vector<std::pair<Eigen::Index, Eigen::Index>> seen;
  ForEachRecord(run.rows.rows(), run.record_starts,
                [&](Eigen::Index begin, Eigen::Index length) { seen.emplace_back(begin, length); });
  EXPECT_EQ(seen, (std::vector<std::pair<Eigen::Index, Eigen::Index>>{{0, 3}, {3, 2}, {5, 3}, {8, 1}}));
  EXPECT_NO_THROW(CheckRecordStarts(run.record_starts, 9));
  EXPECT_THROW(CheckRecordStarts({3, 3}, 9), DataError);
  EXPECT_THROW(CheckRecordStarts({0}, 9), DataError);
  EXPECT_THROW(CheckRecordStarts({9}, 9), DataError);
}

TEST(LoggedRows, AMaskKeepsTheLoggedRowsAndRecordsCarryIt) {
  Eigen::MatrixXd m(4, 2);
  m << 1, 10, 2, 20, 3, 30, 4, 40;
  const std::vector<bool> logged{true, false, false, true};
  const Eigen::MatrixXd kept = LoggedRows(m, logged);
  ASSERT_EQ(kept.rows(), 2);
  EXPECT_EQ(kept(1, 1), 40.0);
  EXPECT_EQ(LoggedRows(m, {}), m);  // empty: every row
  EXPECT_EQ(CountLogged(logged, 4), 2);
  EXPECT_EQ(CountLogged({}, 4), 4);
  EXPECT_THROW(CheckLogged({true, false}, 4), DataError);
  EXPECT_THROW(CheckLogged({false, false}, 2), DataError);

  // A block without a mask after one with a mask counts as logged, and the other way round.
  RecordRows run;
  run.Append(Eigen::MatrixXd::Zero(2, 1));
  EXPECT_TRUE(run.logged.empty());
  run.Append(Eigen::MatrixXd::Zero(3, 1), {}, {true, false, true});
  run.Append(Eigen::MatrixXd::Zero(1, 1));
  EXPECT_EQ(run.logged, (std::vector<bool>{true, true, true, false, true, true}));
  EXPECT_EQ(run.record_starts, (std::vector<Eigen::Index>{2, 5}));
  EXPECT_THROW(run.Append(Eigen::MatrixXd::Zero(2, 1), {}, {true}), DataError);
}

}  // namespace
}  // namespace gyrodrift::drift
