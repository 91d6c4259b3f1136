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
  ASSERT_EQ(r.rows.size(), 8u);  // none and constant first, then ms-elm and poly
  EXPECT_EQ(r.split_index, 700);
  EXPECT_TRUE(r.against_truth);
  for (const auto& row : r.rows) {
    EXPECT_EQ(row.estimate.size(), 300);
    EXPECT_GT(row.rmse, 0.0);
    EXPECT_GE(row.max_abs, row.rmse);
  }
  EXPECT_EQ(r.rows[4].method, Method::kMsElm);
  // Single models do not decompose: both protocols are the same computation.
  EXPECT_EQ(r.rows[6].rmse, r.rows[7].rmse);
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
  ASSERT_EQ(r.rows.size(), 8u);
  DriftOptions elm = o;
  elm.method = Method::kElm;
  const DriftModel single = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), elm);
  EXPECT_EQ(r.rows[6].estimate,
            PredictAhead(single, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal));
  const DriftModel ms = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), o);
  EXPECT_EQ(r.rows[5].estimate,
            PredictAhead(ms, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal, eo.causal));
  eo.horizon = 1;
  const EvaluationResult one = Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo);
  EXPECT_NE(one.rows[4].estimate, r.rows[4].estimate);  // paper protocol: 1 against 6 steps
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

// Compensate mode: no protocol decomposes the test block (the estimate reads temperature only):
// ms-elm's rows do not move when only the test block's output changes (the paper row did until
// 2026-11-27), both are one computation, and no causal-window note is given.
TEST(Evaluation, CompensateModeNeverSeesTheTestBlocksOutput) {
  const Log log = MakeLog(1000, 9);
  EvaluationOptions eo;
  eo.methods = {Method::kMsElm};
  const DriftOptions o = Fast(Mode::kCompensate, Method::kMsElm);
  const EvaluationResult a = Evaluate(log.rate, log.temperature, log.drift, o, eo);
  Eigen::VectorXd changed = log.rate;
  changed.tail(300) += Eigen::VectorXd::LinSpaced(300, 0.0, 1.0);
  const EvaluationResult b = Evaluate(changed, log.temperature, log.drift, o, eo);
  ASSERT_EQ(a.rows.size(), 6u);
  ASSERT_EQ(a.rows[4].method, Method::kMsElm);
  for (size_t i = 4; i < 6; ++i) {
    EXPECT_EQ(a.rows[i].estimate, b.rows[i].estimate) << i;
    EXPECT_TRUE(a.rows[i].notes.empty()) << i;
  }
  EXPECT_EQ(a.rows[4].estimate, a.rows[5].estimate);
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

// A training block that is constant where the whole record is not: the refusal names the block
// the fits see, not the record (which varies).
TEST(Evaluation, AConstantTrainingBlockIsNamedAsTheBlock) {
  Log log = MakeLog(1000, 9);
  EvaluationOptions eo;
  eo.methods = {Method::kPoly};
  const auto message = [&] {
    try {
      Evaluate(log.rate, log.temperature, log.drift, Fast(Mode::kCompensate, Method::kPoly), eo);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  log.rate.head(700).setConstant(1.5);
  EXPECT_EQ(message(),
            "target's training block (samples 1..700) is constant (every sample is 1.5): there is "
            "nothing to fit the methods on");
  log = MakeLog(1000, 9);
  log.temperature.head(700).setConstant(20.0);
  EXPECT_EQ(message(),
            "temperature's training block (samples 1..700) is constant (every sample is 20): a "
            "drift model on temperature needs a training block whose temperature changes");
}

// The slow variation: the RMS of whole blocks' means (a last partial block left out).
TEST(Evaluation, SlowVariationIsTheRmsOfBlockMeans) {
  const Eigen::VectorXd x = (Eigen::VectorXd(5) << 1, 1, 3, 3, 5).finished();
  EXPECT_DOUBLE_EQ(SlowVariation(x, 1.0, 2.0), std::sqrt(5.0));  // means 1 and 3
  EXPECT_DOUBLE_EQ(SlowVariation(x, 0.5, 4.0), std::sqrt(5.0));  // 2 samples per block too
  EXPECT_TRUE(std::isnan(SlowVariation(x, 1.0, 600.0)));         // shorter than a block
  const Eigen::VectorXd estimate = (Eigen::VectorXd(5) << 1, 1, 1, 1, 0).finished();
  // Left: block means 0 and 2, sqrt(2) of sqrt(5).
  EXPECT_DOUBLE_EQ(SlowVariationRemoved(x, estimate, 1.0, 2.0), 1.0 - std::sqrt(2.0 / 5.0));
  EXPECT_EQ(SlowVariationRemoved(x, Eigen::VectorXd::Zero(5), 1.0, 2.0), 0.0);
  EXPECT_THROW(SlowVariationRemoved(x, x.head(4), 1.0, 2.0), DataError);
  EXPECT_THROW(SlowVariation(x, 0.0), OptionError);
}

// none and constant open every table, in both modes, even when not asked for; each row is scored
// against the measured output too, and gives the share of the slow variation removed.
TEST(Evaluation, EveryTableOpensWithNoneAndConstant) {
  const Log log = MakeLog(2000, 11);
  EvaluationOptions eo;
  eo.methods = {Method::kPoly, Method::kConstant};  // constant named: scored once, first
  eo.protocols = {Protocol::kCausal};
  DriftOptions o = Fast(Mode::kCompensate, Method::kPoly);
  o.features.rate_hz = 0.5;  // 10-min blocks of 300 samples: 2 in the 600-sample test block
  EvaluationResult r = Evaluate(log.rate, log.temperature, log.drift, o, eo);
  ASSERT_EQ(r.rows.size(), 3u);
  EXPECT_EQ(r.rows[0].method, Method::kNone);
  EXPECT_EQ(r.rows[1].method, Method::kConstant);
  EXPECT_EQ(r.rows[2].method, Method::kPoly);
  EXPECT_EQ(EvaluatedMethods(eo), (std::vector<Method>{Method::kNone, Method::kConstant,
                                                        Method::kPoly}));
  const Eigen::VectorXd truth = log.drift.tail(600), measured = log.rate.tail(600);
  EXPECT_EQ(r.rows[0].estimate, Eigen::VectorXd::Zero(600));
  EXPECT_DOUBLE_EQ(r.rows[0].rmse, std::sqrt(truth.squaredNorm() / 600.0));
  EXPECT_DOUBLE_EQ(r.rows[0].rmse_measured, std::sqrt(measured.squaredNorm() / 600.0));
  EXPECT_EQ(r.rows[0].slow_removed, 0.0);
  EXPECT_EQ(r.rows[1].estimate, Eigen::VectorXd::Constant(600, log.rate.head(1400).mean()));
  EXPECT_DOUBLE_EQ(r.rows[2].slow_removed,
                   SlowVariationRemoved(truth, r.rows[2].estimate, 0.5));
  EXPECT_NE(r.Table().find("slow_rm"), std::string::npos);
  // Predict mode, without a truth: scored against the output, so rmse_measured is rmse.
  eo.methods = {Method::kTrailingMean};
  r = Evaluate(log.rate, Eigen::MatrixXd(), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kPoly),
               eo);
  ASSERT_EQ(r.rows.size(), 3u);
  for (const auto& row : r.rows) EXPECT_EQ(row.rmse_measured, row.rmse);
  // A filter of the output in compensate mode is refused before any fit.
  eo.methods = {Method::kKalmanLevel};
  EXPECT_THROW(Evaluate(log.rate, log.temperature, log.drift, o, eo), OptionError);
}

}  // namespace
}  // namespace gyrodrift::drift
