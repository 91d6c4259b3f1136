// Predict mode (prediction.cc): the history rule, and the recursive H-step prediction from each
// sub-model's own predictions and each step's thermal inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/features.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

// The first predictable sample: the lags before the origin, the shortest causal window (16) when
// the causal protocol decomposes, and horizon - 1 more steps; single models are causal as they are.
TEST(DriftModel, FirstPredictableCountsTheLagsTheCausalWindowAndTheHorizon) {
  DriftModel model;
  model.lags = 4;
  model.options.method = Method::kMsElm;
  EXPECT_EQ(FirstPredictable(model, Protocol::kPaper, 1), 4);
  EXPECT_EQ(FirstPredictable(model, Protocol::kCausal, 1), 16);
  EXPECT_EQ(FirstPredictable(model, Protocol::kCausal, 12), 27);
  model.lags = 20;
  EXPECT_EQ(FirstPredictable(model, Protocol::kCausal, 1), 20);
  model.lags = 4;
  model.options.method = Method::kElm;
  EXPECT_EQ(FirstPredictable(model, Protocol::kCausal, 3), 6);
  EXPECT_NO_THROW(FirstPredictable(model, Protocol::kPaper, kMaxHorizon));
  EXPECT_THROW(FirstPredictable(model, Protocol::kPaper, 0), UsageError);
  EXPECT_THROW(FirstPredictable(model, Protocol::kPaper, kMaxHorizon + 1), UsageError);
}

// PredictFromSeries on a single model's one sub-series, the record itself, is PredictAhead; it
// refuses a first sample without its history, and PredictAhead a compensate-mode model.
TEST(DriftModel, PredictFromSeriesIsPredictAheadOnTheSubSeriesAndNeedsItsHistory) {
  const Log log = MakeLog(600, 10);
  const DriftModel model =
      FitDriftModel(log.rate.head(400), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kPoly));
  ASSERT_EQ(model.lags, 4);
  const Eigen::MatrixXd no_thermal(600, 0);
  EXPECT_EQ(PredictFromSeries(model, log.rate, no_thermal, 420, 180, 3),
            PredictAhead(model, log.rate, Eigen::VectorXd(), 420, 3, Protocol::kPaper));
  EXPECT_NO_THROW(PredictFromSeries(model, log.rate, no_thermal, 6, 10, 3));
  EXPECT_THROW(PredictFromSeries(model, log.rate, no_thermal, 5, 10, 3), DataError);
  const DriftModel compensate =
      FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kPoly));
  EXPECT_THROW(PredictAhead(compensate, log.rate, log.temperature, 100, 1, Protocol::kPaper),
               UsageError);
}

// Recursive multi-step prediction: a linear autoregression on 4 lags represents a sampled sine
// exactly, so fed its own predictions it still continues the sine 12 steps ahead; a mistake in
// the recursion (a lag in the wrong place, the wrong thermal row) would not.
TEST(DriftModel, PredictAheadContinuesASineFromItsOwnPredictions) {
  const Eigen::Index n = 600;
  Eigen::VectorXd y(n);
  for (Eigen::Index t = 0; t < n; ++t) y[t] = std::sin(2 * std::numbers::pi * t / 37.0);
  DriftOptions o = Fast(Mode::kPredict, Method::kPoly);
  o.learner.poly_degree = 1;
  const DriftModel model = FitDriftModel(y.head(400), Eigen::VectorXd(), o);
  for (int horizon : {1, 2, 12}) {
    const Eigen::VectorXd ahead =
        PredictAhead(model, y, Eigen::VectorXd(), 420, horizon, Protocol::kPaper);
    ASSERT_EQ(ahead.size(), n - 420);
    EXPECT_LT((ahead - y.tail(n - 420)).cwiseAbs().maxCoeff(), 1e-6) << horizon;
  }
  // Horizon 1 is the classic one-step prediction: the learner on the lag rows, nothing more.
  EXPECT_EQ(PredictAhead(model, y, Eigen::VectorXd(), 420, 1, Protocol::kCausal),
            model.sub_models.front().learner->Predict(LagRows(y, model.lags, 420, n - 420)));
  // The 12-step prediction of y[t] starts at t - 11: it needs lags + 11 samples before t.
  EXPECT_NO_THROW(PredictAhead(model, y, Eigen::VectorXd(), 15, 12, Protocol::kPaper));
  EXPECT_THROW(PredictAhead(model, y, Eigen::VectorXd(), 14, 12, Protocol::kPaper), DataError);
  EXPECT_THROW(PredictAhead(model, y, Eigen::VectorXd(), 420, 0, Protocol::kPaper), UsageError);
}

// With a temperature, every step of the recursion reads the thermal inputs of its own time: an
// output that is a linear function of the temperature one sample earlier is predicted exactly
// 6 steps ahead (the inputs of the origin would miss it by the temperature's change).
TEST(DriftModel, PredictAheadReadsEachStepsThermalInputs) {
  const Eigen::Index n = 800;
  Eigen::VectorXd temperature(n), y(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    temperature[t] = 20.0 + 10.0 * std::sin(2 * std::numbers::pi * t / 300.0) + 0.02 * t;
  }
  y[0] = 0.0;
  for (Eigen::Index t = 1; t < n; ++t) y[t] = 0.3 * (temperature[t - 1] - 20.0);
  DriftOptions o = Fast(Mode::kPredict, Method::kPoly);
  o.learner.poly_degree = 1;
  o.features.use_temperature = true;
  const DriftModel model = FitDriftModel(y.head(500), temperature.head(500), o);
  ASSERT_TRUE(model.uses_temperature());
  const Eigen::VectorXd ahead = PredictAhead(model, y, temperature, 520, 6, Protocol::kPaper);
  EXPECT_LT((ahead - y.tail(n - 520)).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace gyrodrift::drift
