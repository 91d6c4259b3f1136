// Compensate mode (compensation.cc): the drift estimated from temperature alone, identified per
// group, referenced on request, with a band where the sub-models are identified, records
// estimated apart, and the share of a record outside the training temperatures.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/features.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

TEST(DriftModel, CompensateModeNeedsOnlyTemperatureAtRunTime) {
  const Log train = MakeLog(3000, 3);
  for (Method method : {Method::kMsElm, Method::kElm, Method::kPoly}) {
    const DriftModel model =
        FitDriftModel(train.rate, train.temperature, Fast(Mode::kCompensate, method));
    const Log test = MakeLog(3000, 4);  // same programme, new noise
    const Eigen::VectorXd estimate = EstimateDrift(model, test.temperature);
    const double rms_drift = std::sqrt(test.drift.squaredNorm() / 3000);
    const double rms_error = std::sqrt((estimate - test.drift).squaredNorm() / 3000);
    EXPECT_LT(rms_error, 0.3 * rms_drift) << ToString(method) << ": " << model.Summary();
  }
}

TEST(DriftModel, CompensateModeIdentifiesEveryGroupReferencesOnRequestAndIsThreadCountFree) {
  const Log train = MakeLog(3000, 8);
  DriftOptions o = Fast(Mode::kCompensate, Method::kMsElm);
  const DriftModel model = FitDriftModel(train.rate, train.temperature, o);
  ASSERT_GE(model.sub_models.size(), 2u) << model.Summary();
  EXPECT_TRUE(model.identified());
  for (const SubModel& sub : model.sub_models) {
    ASSERT_TRUE(sub.thermal) << sub.name << ": every group has its own identified thermal model";
    EXPECT_FALSE(sub.learner) << sub.name;
  }
  // The fitted intercept is kept by default: the estimate in equilibrium is the unit's bias.
  EXPECT_FALSE(o.reference_c);
  const Eigen::VectorXd estimate = EstimateDrift(model, train.temperature);
  // Referenced: a record in equilibrium at 20 degC has no thermal drift, and referencing only
  // shifts the estimate by a constant.
  o.reference_c = 20.0;
  const DriftModel referenced = FitDriftModel(train.rate, train.temperature, o);
  const Eigen::VectorXd at_reference =
      EstimateDrift(referenced, Eigen::VectorXd::Constant(500, 20.0));
  EXPECT_LE(at_reference.cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::VectorXd shifted = EstimateDrift(referenced, train.temperature);
  EXPECT_LE(((shifted - estimate).array() - (shifted - estimate).mean()).abs().maxCoeff(), 1e-10);
  // One thread or two: the same bits.
  o.reference_c.reset();
  EXPECT_EQ(EstimateDrift(FitDriftModel(train.rate, train.temperature, o, {}, {.threads = 1}),
                          train.temperature),
            estimate);
  EXPECT_EQ(EstimateDrift(FitDriftModel(train.rate, train.temperature, o, {}, {.threads = 2}),
                          train.temperature),
            estimate);
  // The nonlinear option: each group is still identified, and the blocked cross-validation
  // decides whether it keeps a correction (one only where it lowered the error).
  o.linear_compensation = false;
  const DriftModel nonlinear = FitDriftModel(train.rate, train.temperature, o);
  ASSERT_TRUE(nonlinear.identified());
  for (const SubModel& sub : nonlinear.sub_models) {
    const CalibrationReport& r = sub.thermal->report;
    // (tried wherever there is a regressor beside the intercept)
    EXPECT_EQ(std::isnan(r.cv_rmse_nonlinear), sub.thermal->coefficients.size() == 1) << sub.name;
    EXPECT_EQ(sub.thermal->correction != nullptr, r.nonlinear_units > 0) << sub.name;
    if (sub.thermal->correction) {
      EXPECT_LT(r.cv_rmse_nonlinear, r.cv_rmse) << sub.name;
    }
  }
  o.reference_c = 300.0;
  EXPECT_THROW(o.Validate(), UsageError);
  o.reference_c = std::nan("");  // set, so a temperature: NaN is none
  EXPECT_THROW(o.Validate(), UsageError);
}

TEST(DriftModel, ThermalMethodIsCompensateOnlyAndTakesSeveralChannels) {
  const Log train = MakeLog(3000, 8);
  DriftOptions o = Fast(Mode::kPredict, Method::kThermal);
  EXPECT_THROW(o.Validate(), UsageError);
  o.mode = Mode::kCompensate;
  Eigen::MatrixXd two(train.temperature.size(), 2);
  two.col(0) = train.temperature;
  Eigen::VectorXd lagged(train.temperature.size());
  FirstOrderLag(train.temperature, 400.0, 1.0, lagged);
  two.col(1) = lagged;
  const DriftModel model = FitDriftModel(train.rate, two, o);
  EXPECT_EQ(model.temperature_channels(), 2);
  EXPECT_EQ(EstimateDrift(model, two).size(), two.rows());
  EXPECT_THROW(EstimateDrift(model, train.temperature), DataError);
  // Feature-based methods take one channel and say so.
  o.method = Method::kPoly;
  EXPECT_THROW(FitDriftModel(train.rate, two, o), UsageError);
}

// The band (column 1) adds the identified sub-models' standard deviations; a learner on features
// has none. With record starts each record is estimated alone, its lags starting in equilibrium.
TEST(DriftModel, EstimateWithSdHasABandForIdentifiedModelsAndRestartsAtEachRecord) {
  const Log train = MakeLog(3000, 8);
  const DriftModel thermal =
      FitDriftModel(train.rate, train.temperature, Fast(Mode::kCompensate, Method::kThermal));
  const Eigen::MatrixXd e = EstimateDriftWithSd(thermal, train.temperature);
  ASSERT_EQ(e.cols(), 2);
  EXPECT_EQ(Eigen::VectorXd(e.col(0)), EstimateDrift(thermal, train.temperature));
  EXPECT_TRUE(e.col(1).allFinite());
  EXPECT_GE(e.col(1).minCoeff(), 0.0);
  const Eigen::MatrixXd records = EstimateDriftWithSd(thermal, train.temperature, {1000});
  EXPECT_EQ(Eigen::MatrixXd(records.topRows(1000)),
            EstimateDriftWithSd(thermal, train.temperature.head(1000)));
  EXPECT_EQ(Eigen::MatrixXd(records.bottomRows(2000)),
            EstimateDriftWithSd(thermal, train.temperature.tail(2000)));
  EXPECT_NE(Eigen::VectorXd(records.col(0)), Eigen::VectorXd(e.col(0)));
  EXPECT_THROW(EstimateDrift(thermal, train.temperature, {0}), DataError);

  const DriftModel poly =
      FitDriftModel(train.rate, train.temperature, Fast(Mode::kCompensate, Method::kPoly));
  EXPECT_TRUE(EstimateDriftWithSd(poly, train.temperature).col(1).array().isNaN().all());
  const DriftModel predict =
      FitDriftModel(train.rate, Eigen::VectorXd(), Fast(Mode::kPredict, Method::kPoly));
  EXPECT_THROW(EstimateDrift(predict, train.temperature), UsageError);
}

TEST(DriftModel, ShareOutsideRangeCountsSamplesOutsideTheClosedRange) {
  Eigen::VectorXd t(5);
  t << 1.0, 2.0, 2.5, 3.0, 4.0;
  EXPECT_EQ(ShareOutsideRange(t, 2.0, 3.0), 0.4);
  EXPECT_EQ(ShareOutsideRange(t, 0.0, 10.0), 0.0);
  EXPECT_EQ(ShareOutsideRange(t, 3.0, 2.0), 0.0);  // an empty range: no temperature model
  EXPECT_EQ(ShareOutsideRange(Eigen::VectorXd(), 0.0, 1.0), 0.0);
}

}  // namespace
}  // namespace gyrodrift::drift
