// Baselines a reviewer compares a drift model against: causal filters of the measured series
// itself (no decomposition, no temperature), and the two references every evaluation shows.
//
//   none           0: doing nothing (predict and compensate mode)
//   constant       the training block's mean (both modes; in compensate mode the bias alone)
//   persistence    the last sample
//   trailing-mean  the mean of the last W samples; W from the geometric grid 16 * 2^(k/2),
//                  k = 0..16 (16..4096 samples), at most the training block's length
//   exp-smoothing  simple exponential smoothing, level l_j = l_{j-1} + a_j (y_j - l_{j-1}) with
//                  a_j = max(alpha, 1 / (j + 1)) (a running mean until 1 / (j + 1) < alpha, so the
//                  start needs no guess); alpha from the grid 2^(-k/2), k = 0..28 (1 .. 6.1e-5)
//   kalman-level   local-level model (random-walk level plus white noise), Kalman filter
//   kalman-trend   local-linear-trend model (level and slope random walks plus white noise)
// (Harvey, Forecasting, structural time series models and the Kalman filter, 1989, ch. 2-3;
// Durbin & Koopman, Time series analysis by state space methods, 2nd ed. 2012, ch. 2 and 7.)
//
// Choices on the training block y (N samples): W and alpha minimise the one-step-ahead RMSE
// against the measured samples y[j], j in [N/4, N) (the first quarter warms the filters up; the
// smallest W or largest alpha wins a tie). The Kalman variances maximise the likelihood, the
// observation variance concentrated out (Harvey 3.4.5): the ratios q/r (level, and slope for the
// trend model) on a grid of whole decades (level 1e-16..1e2, slope 1e-20..1e-2), then refined to
// 1/8 decade within a decade of the best. Initialisation is diffuse (prior variance 1e7 r, the
// first one or two innovations left out of the likelihood).
// All forecasts are causal by construction: the prediction of y[t] made h steps ahead, from the
// origin o = t - h + 1, reads y[0 .. o-1] only. h steps ahead every baseline is flat (its level)
// but kalman-trend, which adds h slopes.
// Units: those of y (variances in y's units squared, per sample). Cost: a forecast is O(N); a fit
// O(N) per candidate: 17 windows, 29 smoothing constants, 35 level ratios (kalman-level) or
// 361 + 288 pairs of level and slope ratios (kalman-trend).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

namespace gyrodrift::drift {

enum class Method;

// none, constant, persistence, trailing-mean, exp-smoothing, kalman-level, kalman-trend.
bool IsBaseline(Method method);

struct Baseline {
  Method method{};
  double constant = 0.0;  // constant: the training mean, units of y
  int window = 0;         // trailing-mean: W, samples
  double alpha = 0.0;     // exp-smoothing: the smoothing constant, in (0, 1]
  // kalman-level, kalman-trend: variances per sample of the level and slope steps and of the
  // observation noise (slope_var 0 for kalman-level), units of y squared.
  double level_var = 0.0, slope_var = 0.0, noise_var = 0.0;
  // What chose the parameters: the one-step validation RMSE (trailing-mean, exp-smoothing) or
  // the log-likelihood (Kalman) of the choice; NaN for the others.
  double criterion = std::numeric_limits<double>::quiet_NaN();
  void Validate() const;        // throws DataError naming a field out of range
  std::string Summary() const;  // one line
  bool operator==(const Baseline&) const = default;
};

// Fits a baseline of `method` (IsBaseline) on the training block y (at least 32 finite samples).
// Throws UsageError for another method, DataError for too short or non-finite y.
Baseline FitBaseline(Method method, const Eigen::Ref<const Eigen::VectorXd>& y);

// Predictions of y[t], t = first .. first + count - 1, each made `horizon` steps ahead from the
// origin o = t - horizon + 1 out of y[0 .. o-1] (the filters start at y[0]). Needs
// first - horizon + 1 >= 1 and first + count <= y.size() + horizon - 1 (samples at and after an
// origin are never read), else DataError.
Eigen::VectorXd ForecastBaseline(const Baseline& baseline,
                                 const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index first,
                                 Eigen::Index count, int horizon);

// The Kalman filter of the local-level (slope_var = 0, no slope state) or local-linear-trend
// model started diffuse at y[0]: row j holds the filtered level and slope after y[j], and the
// innovation y[j] - prediction and its variance (NaN for the diffuse first one or two). Exposed
// for the tests' hand-computed cases.
Eigen::MatrixXd KalmanFilterStates(const Eigen::Ref<const Eigen::VectorXd>& y, bool trend,
                                   double level_var, double slope_var, double noise_var);

}  // namespace gyrodrift::drift
