// Evaluate (evaluation.cc): both protocols in one table scored against the truth, predictions
// ahead with a horizon, and where the test temperature leaves the training range.
#include "gyrodrift/drift/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

TEST(Evaluation, ReportsBothProtocolsAndScoresAgainstTruth) {
  const Log log = MakeLog(1000, 7);
  EvaluationOptions eo;
  eo.methods = {Method::kMsElm, Method::kPoly};
  eo.causal.window = 128;
  const EvaluationResult r =
      Evaluate(log.rate, Eigen::VectorXd(), log.drift, Fast(Mode::kPredict, Method::kMsElm), eo);
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_EQ(r.split_index, 700);
  EXPECT_TRUE(r.against_truth);
  for (const auto& row : r.rows) {
    EXPECT_EQ(row.estimate.size(), 300);
    EXPECT_GT(row.rmse, 0.0);
    EXPECT_GE(row.max_abs, row.rmse);
  }
  // Single models do not decompose: both protocols are the same computation.
  EXPECT_EQ(r.rows[2].rmse, r.rows[3].rmse);
  EXPECT_NE(r.Table().find("ms-elm"), std::string::npos);
  EXPECT_TRUE(std::isnan(r.training_temperature_min_c));  // no temperature given
  EXPECT_EQ(r.test_outside_training_temperature_share, 0.0);
}

// With a horizon, both protocols score PredictAhead's predictions: the causal row is the model
// fitted on the training block predicting 6 steps ahead, the paper row the same recursion from
// the whole record's sub-series; compensate mode has no horizon.
TEST(Evaluation, ScoresPredictionsAheadWithAHorizon) {
  const Log log = MakeLog(1000, 8);
  EvaluationOptions eo;
  eo.methods = {Method::kMsElm, Method::kElm};
  eo.causal.window = 128;
  eo.horizon = 6;
  const DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  const EvaluationResult r = Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo);
  ASSERT_EQ(r.rows.size(), 4u);
  DriftOptions elm = o;
  elm.method = Method::kElm;
  const DriftModel single = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), elm);
  EXPECT_EQ(r.rows[2].estimate,
            PredictAhead(single, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal));
  const DriftModel ms = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), o);
  EXPECT_EQ(r.rows[1].estimate,
            PredictAhead(ms, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal, eo.causal));
  eo.horizon = 1;
  const EvaluationResult one = Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo);
  EXPECT_NE(one.rows[0].estimate, r.rows[0].estimate);  // paper protocol: 1 against 6 steps
  eo.horizon = 2;
  EXPECT_THROW(
      Evaluate(log.rate, log.temperature, log.drift, Fast(Mode::kCompensate, Method::kPoly), eo),
      UsageError);
  eo.horizon = 0;
  EXPECT_THROW(eo.Validate(), UsageError);
  // A horizon reaching back past the training block's history is refused before any fit.
  eo.horizon = 690;
  EXPECT_THROW(Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo), OptionError);
  // The causal options are checked as PredictAhead checks them.
  eo.horizon = 1;
  eo.causal.ensemble_size = -1;
  EXPECT_THROW(eo.Validate(), OptionError);
}

TEST(Evaluation, SaysWhereTheTestTemperatureLeavesTheTrainingRange) {
  Log log = MakeLog(1000, 9);
  // A slow warming on top of the cycle: the last 300 samples reach above anything before them.
  for (Eigen::Index t = 0; t < 1000; ++t) log.temperature[t] += 0.02 * static_cast<double>(t);
  EvaluationOptions eo;
  eo.methods = {Method::kPoly};
  const EvaluationResult r =
      Evaluate(log.rate, log.temperature, log.drift, Fast(Mode::kCompensate, Method::kPoly), eo);
  EXPECT_EQ(r.training_temperature_max_c, log.temperature.head(700).maxCoeff());
  const double expected =
      static_cast<double>(
          (log.temperature.tail(300).array() > r.training_temperature_max_c).count()) /
      300.0;
  EXPECT_GT(expected, 0.2);
  EXPECT_EQ(r.test_outside_training_temperature_share, expected);
  EXPECT_EQ(ShareOutsideRange(log.temperature, std::nan(""), std::nan("")), 0.0);
}

}  // namespace
}  // namespace gyrodrift::drift
