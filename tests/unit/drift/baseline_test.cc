// The baselines (baseline.cc): forecasts against hand-computed cases, the Kalman filter against
// its closed forms, the fits' choices on series whose best choice is known, causality, and the
// baselines as drift models (fit, predict, compensate).
#include "gyrodrift/drift/baseline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {
namespace {

const Eigen::VectorXd kY = (Eigen::VectorXd(5) << 1.0, 2.0, 4.0, 7.0, 11.0).finished();

Baseline Made(Method method) {
  Baseline b;
  b.method = method;
  return b;
}

TEST(Baseline, PersistenceRepeatsTheLastSampleBeforeTheOrigin) {
  const Baseline b = Made(Method::kPersistence);
  EXPECT_EQ(ForecastBaseline(b, kY, 2, 3, 1), (Eigen::VectorXd(3) << 2, 4, 7).finished());
  // Two steps ahead: y[t] from y[t - 2].
  EXPECT_EQ(ForecastBaseline(b, kY, 2, 3, 2), (Eigen::VectorXd(3) << 1, 2, 4).finished());
}

TEST(Baseline, TrailingMeanAveragesWhatTheWindowHolds) {
  Baseline b = Made(Method::kTrailingMean);
  b.window = 2;
  // Origins 1..4: mean(1), mean(1, 2), mean(2, 4), mean(4, 7).
  EXPECT_EQ(ForecastBaseline(b, kY, 1, 4, 1), (Eigen::VectorXd(4) << 1, 1.5, 3, 5.5).finished());
  EXPECT_EQ(ForecastBaseline(b, kY, 4, 1, 3), (Eigen::VectorXd(1) << 1.5).finished());
}

TEST(Baseline, ExponentialSmoothingStartsAsARunningMean) {
  Baseline b = Made(Method::kExpSmoothing);
  b.alpha = 0.5;
  // Gains max(0.5, 1 / (j + 1)): 1, 0.5, 0.5, 0.5 -> levels 1, 1.5, 2.75, 4.875.
  EXPECT_EQ(ForecastBaseline(b, kY, 1, 4, 1),
            (Eigen::VectorXd(4) << 1, 1.5, 2.75, 4.875).finished());
  // Flat ahead: three steps ahead of y[3] and y[4] are the levels after y[0] and y[1].
  EXPECT_EQ(ForecastBaseline(b, kY, 3, 2, 3), (Eigen::VectorXd(2) << 1, 1.5).finished());
  b.alpha = 0.1;  // a running mean throughout (1 / (j + 1) >= 0.2 > 0.1)
  EXPECT_DOUBLE_EQ(ForecastBaseline(b, kY, 5, 1, 1)[0], kY.mean());
}

TEST(Baseline, NoneAndConstantIgnoreTheRecord) {
  Baseline c = Made(Method::kConstant);
  c.constant = 3.5;
  EXPECT_EQ(ForecastBaseline(c, kY, 1, 3, 1), Eigen::VectorXd::Constant(3, 3.5));
  EXPECT_EQ(ForecastBaseline(Made(Method::kNone), kY, 1, 3, 1), Eigen::VectorXd::Zero(3));
}

// Local level, q = r = 1, y = 1, 3, 2: diffuse start a = 1, P = 1; then P- = 2, F = 3, K = 2/3,
// a = 7/3, P = 2/3; P- = 5/3, F = 8/3, K = 5/8, v = -1/3, a = 51/24.
TEST(Baseline, KalmanLocalLevelMatchesTheHandComputedFilter) {
  const Eigen::VectorXd y = (Eigen::VectorXd(3) << 1, 3, 2).finished();
  const Eigen::MatrixXd f = KalmanFilterStates(y, false, 1.0, 0.0, 1.0);
  EXPECT_DOUBLE_EQ(f(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(f(0, 2)));  // the diffuse start has no innovation
  EXPECT_NEAR(f(1, 0), 7.0 / 3.0, 1e-14);
  EXPECT_DOUBLE_EQ(f(1, 2), 2.0);
  EXPECT_DOUBLE_EQ(f(1, 3), 3.0);
  EXPECT_NEAR(f(2, 0), 51.0 / 24.0, 1e-14);
  EXPECT_NEAR(f(2, 2), -1.0 / 3.0, 1e-14);
  EXPECT_NEAR(f(2, 3), 8.0 / 3.0, 1e-14);
  EXPECT_EQ(f.col(1), Eigen::VectorXd::Zero(3));  // no slope
  Baseline b = Made(Method::kKalmanLevel);
  b.level_var = 1.0;
  b.noise_var = 1.0;
  EXPECT_NEAR(ForecastBaseline(b, y, 3, 1, 1)[0], 51.0 / 24.0, 1e-14);
  EXPECT_NEAR(ForecastBaseline(b, y, 4, 1, 2)[0], 51.0 / 24.0, 1e-14);  // flat ahead
}

// Its steady state is exponential smoothing with the gain P / (P + r), P the positive root of
// P^2 - qP - qr = 0 (Harvey 1989, 2.3.4): the innovation variance settles at P + r.
TEST(Baseline, KalmanLocalLevelSettlesAtItsSteadyStateGain) {
  const double q = 0.01, r = 2.0;
  const Eigen::MatrixXd f = KalmanFilterStates(Eigen::VectorXd::Zero(400), false, q, 0.0, r);
  const double p = 0.5 * (q + std::sqrt(q * q + 4.0 * q * r));
  EXPECT_NEAR(f(399, 3), p + r, 1e-12);
}

// Local linear trend without disturbances on y = 0, 1, 2, 3 (r = 1) is least squares on a line:
// after y[1] level 1, slope 1; after y[2] the covariance of the fitted end point and slope is
// r [[1/3 + 1/2, 1/2], [1/2, 1/2]] (5/6, 1/2, 1/2); h steps ahead adds h slopes.
TEST(Baseline, KalmanTrendIsLeastSquaresOnALineWithoutDisturbances) {
  const Eigen::VectorXd y = (Eigen::VectorXd(4) << 0, 1, 2, 3).finished();
  const Eigen::MatrixXd f = KalmanFilterStates(y, true, 0.0, 0.0, 1.0);
  EXPECT_DOUBLE_EQ(f(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(f(1, 1), 1.0);
  EXPECT_TRUE(std::isnan(f(1, 3)));  // the second sample completes the diffuse start
  // At y[2]: predicted 2 (v = 0), predicted variance 5 + r.
  EXPECT_DOUBLE_EQ(f(2, 2), 0.0);
  EXPECT_DOUBLE_EQ(f(2, 3), 6.0);
  // At y[3] the prediction's variance is that of a line fitted to 3 points, extrapolated one step
  // (5/6 + 2 * 1/2 + 1/2 = 7/3), plus r.
  EXPECT_DOUBLE_EQ(f(3, 3), 7.0 / 3.0 + 1.0);
  Baseline b = Made(Method::kKalmanTrend);
  b.noise_var = 1.0;
  EXPECT_DOUBLE_EQ(ForecastBaseline(b, y, 5, 1, 2)[0], 5.0);  // level 3 + 2 slopes of 1
  EXPECT_DOUBLE_EQ(ForecastBaseline(b, y, 4, 1, 1)[0], 4.0);
}

Eigen::VectorXd WhiteNoise(Eigen::Index n, double sd, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, sd);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = normal(rng);
  return x;
}

Eigen::VectorXd RandomWalk(Eigen::Index n, double step_sd, unsigned seed) {
  Eigen::VectorXd x = WhiteNoise(n, step_sd, seed);
  for (Eigen::Index i = 1; i < n; ++i) x[i] += x[i - 1];
  return x;
}

// White noise about a constant: the longest window and the smallest constant average best; a
// random walk: the shortest window and the largest constant follow it best.
TEST(Baseline, ValidationChoosesTheSmoothingTheSeriesCallsFor) {
  const Eigen::VectorXd noise = WhiteNoise(8192, 1.0, 3).array() + 5.0;
  const Eigen::VectorXd walk = RandomWalk(8192, 1.0, 4);
  EXPECT_GE(FitBaseline(Method::kTrailingMean, noise).window, 1024);
  EXPECT_EQ(FitBaseline(Method::kTrailingMean, walk).window, 16);
  EXPECT_LE(FitBaseline(Method::kExpSmoothing, noise).alpha, std::pow(2.0, -10.0));
  EXPECT_DOUBLE_EQ(FitBaseline(Method::kExpSmoothing, walk).alpha, 1.0);
  const Baseline c = FitBaseline(Method::kConstant, noise);
  EXPECT_DOUBLE_EQ(c.constant, noise.mean());
  // A short block caps the window at its length.
  EXPECT_LE(FitBaseline(Method::kTrailingMean, noise.head(40)).window, 40);
}

// Maximum likelihood recovers the variances of a simulated local-level series.
TEST(Baseline, KalmanMaximumLikelihoodRecoversTheVariances) {
  const Eigen::Index n = 20000;
  const Eigen::VectorXd y = RandomWalk(n, 0.1, 5) + WhiteNoise(n, 1.0, 6);  // q 0.01, r 1
  const Baseline level = FitBaseline(Method::kKalmanLevel, y);
  EXPECT_NEAR(level.noise_var, 1.0, 0.1);
  EXPECT_GT(level.level_var, 0.01 / 2.0);
  EXPECT_LT(level.level_var, 0.01 * 2.0);
  EXPECT_EQ(level.slope_var, 0.0);
  // The trend model finds next to no slope variance in a series without one.
  const Baseline trend = FitBaseline(Method::kKalmanTrend, y.head(8000));
  EXPECT_NEAR(trend.noise_var, 1.0, 0.1);
  EXPECT_LT(trend.slope_var, 1e-3 * trend.level_var);
  EXPECT_GT(trend.level_var, 0.01 / 2.0);
}

// Nothing at or after an origin reaches its forecast.
TEST(Baseline, EveryForecastIsCausal) {
  const Eigen::VectorXd y = RandomWalk(600, 1.0, 7) + WhiteNoise(600, 0.5, 8);
  for (Method m : {Method::kPersistence, Method::kTrailingMean, Method::kExpSmoothing,
                   Method::kKalmanLevel, Method::kKalmanTrend}) {
    const Baseline b = FitBaseline(m, y.head(400));
    for (int h : {1, 10}) {
      const Eigen::VectorXd f = ForecastBaseline(b, y, 400, 200, h);
      Eigen::VectorXd changed = y;
      changed.tail(600 - (500 - h + 1)).setConstant(1e6);  // from the origin of y[500] on
      const Eigen::VectorXd g = ForecastBaseline(b, changed, 400, 200, h);
      EXPECT_EQ(f.head(101), g.head(101)) << ToString(m) << " h " << h;
      EXPECT_NE(f.tail(99), g.tail(99)) << ToString(m) << " h " << h;
    }
  }
}

TEST(Baseline, RefusesWhatItCannotDo) {
  EXPECT_THROW(FitBaseline(Method::kElm, kY), UsageError);
  EXPECT_THROW(FitBaseline(Method::kTrailingMean, kY), DataError);  // fewer than 32 samples
  const Baseline p = Made(Method::kPersistence);
  EXPECT_THROW(ForecastBaseline(p, kY, 0, 1, 1), DataError);  // no sample before the origin
  EXPECT_THROW(ForecastBaseline(p, kY, 4, 3, 1), DataError);  // beyond the record
  Baseline bad = Made(Method::kExpSmoothing);
  bad.alpha = 1.5;
  EXPECT_THROW(bad.Validate(), DataError);
  Baseline level = Made(Method::kKalmanLevel);
  level.noise_var = 1.0;
  level.slope_var = 1.0;
  EXPECT_THROW(level.Validate(), DataError);
}

// As drift models: fit and predict go through the baseline; none and constant estimate a
// compensation too; the filters are predict mode's only and read no temperature.
TEST(Baseline, RunsAsADriftModelInBothModes) {
  const Eigen::VectorXd y = RandomWalk(800, 0.1, 9) + WhiteNoise(800, 1.0, 10);
  const Eigen::VectorXd temperature = Eigen::VectorXd::LinSpaced(800, 20.0, 40.0);
  DriftOptions o;
  o.method = Method::kTrailingMean;
  o.features.use_temperature = true;  // ignored: a baseline reads no temperature
  const DriftModel model = FitDriftModel(y.head(500), Eigen::VectorXd(), o);
  ASSERT_EQ(model.sub_models.size(), 1u);
  ASSERT_TRUE(model.sub_models[0].baseline);
  EXPECT_FALSE(model.uses_temperature());
  EXPECT_NE(model.Summary().find("mean of the last"), std::string::npos);
  const Baseline& b = *model.sub_models[0].baseline;
  EXPECT_EQ(b, FitBaseline(Method::kTrailingMean, y.head(500)));
  for (int h : {1, 10}) {
    EXPECT_EQ(PredictAhead(model, y, Eigen::VectorXd(), 500, h, Protocol::kCausal),
              ForecastBaseline(b, y, 500, 300, h));
  }
  EXPECT_EQ(FirstPredictable(model, Protocol::kCausal, 10), 10);

  o = DriftOptions();
  o.mode = Mode::kCompensate;
  o.method = Method::kConstant;
  const DriftModel constant = FitDriftModel(y.head(500), temperature.head(500), o);
  EXPECT_EQ(EstimateDrift(constant, temperature),
            Eigen::VectorXd::Constant(800, y.head(500).mean()));
  o.method = Method::kNone;
  EXPECT_EQ(EstimateDrift(FitDriftModel(y, temperature, o), temperature),
            Eigen::VectorXd::Zero(800));
  o.method = Method::kPersistence;
  EXPECT_THROW(FitDriftModel(y, temperature, o), UsageError);
  EXPECT_FALSE(SupportsMode(Method::kKalmanTrend, Mode::kCompensate));
  EXPECT_TRUE(SupportsMode(Method::kConstant, Mode::kCompensate));
}

}  // namespace
}  // namespace gyrodrift::drift
