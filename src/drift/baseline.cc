// The baselines of baseline.h: their fits (validation grids, Kalman maximum likelihood) and their
// causal forecasts.
#include "gyrodrift/drift/baseline.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "../common/format.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kLongestWindow = 4096;

using gyrodrift::internal::Format;

// The candidate of least one-step RMSE (the first of equal ones: the grids run from the smaller
// window and the larger constant); `criterion` receives its RMSE.
template <class T, class F>
T BestOnGrid(const std::vector<T>& candidates, F rmse_of, double& criterion) {
  T best = candidates.front();
  criterion = std::numeric_limits<double>::infinity();
  for (const T& c : candidates) {
    const double rmse = rmse_of(c);
    if (rmse < criterion) {
      criterion = rmse;
      best = c;
    }
  }
  return best;
}

bool IsKalman(Method m) { return m == Method::kKalmanLevel || m == Method::kKalmanTrend; }

// The first sample the validation of a window or a smoothing constant scores: the first quarter
// of the training block warms the filters up.
Eigen::Index ValidationStart(Eigen::Index n) { return n / 4; }

// The level of exponential smoothing after each sample (row j: after y[j]).
Eigen::VectorXd SmoothedLevels(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index end,
                               double alpha) {
  Eigen::VectorXd level(end);
  double l = 0.0;
  for (Eigen::Index j = 0; j < end; ++j) {
    // A running mean until 1 / (j + 1) falls below alpha: no starting guess to tune.
    const double a = std::max(alpha, 1.0 / static_cast<double>(j + 1));
    l += a * (y[j] - l);
    level[j] = l;
  }
  return level;
}

// Means of the last `window` samples before each origin o in [1, end]: entry o - 1 holds the mean
// of y[max(0, o - W) .. o - 1]. Sums run about y[0] so that long records keep their precision.
Eigen::VectorXd TrailingMeans(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index end,
                              int window) {
  Eigen::VectorXd prefix(end + 1);
  prefix[0] = 0.0;
  for (Eigen::Index j = 0; j < end; ++j) prefix[j + 1] = prefix[j] + (y[j] - y[0]);
  Eigen::VectorXd mean(end);
  for (Eigen::Index o = 1; o <= end; ++o) {
    const Eigen::Index from = std::max<Eigen::Index>(0, o - window);
    mean[o - 1] = y[0] + (prefix[o] - prefix[from]) / static_cast<double>(o - from);
  }
  return mean;
}

// One-step RMSE of `after` (the forecast made after sample j, of y[j + 1]) over the validation
// samples.
double OneStepRmse(const Eigen::Ref<const Eigen::VectorXd>& y,
                   const Eigen::Ref<const Eigen::VectorXd>& after) {
  const Eigen::Index start = std::max<Eigen::Index>(1, ValidationStart(y.size()));
  double sum = 0.0;
  for (Eigen::Index j = start; j < y.size(); ++j) {
    const double e = y[j] - after[j - 1];
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(y.size() - start));
}

struct Likelihood {
  double log_likelihood = -std::numeric_limits<double>::infinity();
  double noise_var = 0.0;  // the concentrated-out observation variance
};

// The concentrated log-likelihood of the local-level (trend false) or local-linear-trend model
// with variance ratios q_level = level_var / noise_var and q_slope (Harvey 1989, 3.4.5).
Likelihood ConcentratedLikelihood(const Eigen::Ref<const Eigen::VectorXd>& y, bool trend,
                                  double q_level, double q_slope) {
  const Eigen::MatrixXd f = KalmanFilterStates(y, trend, q_level, trend ? q_slope : 0.0, 1.0);
  double weighted = 0.0, log_f = 0.0;
  Eigen::Index m = 0;
  for (Eigen::Index j = 0; j < f.rows(); ++j) {
    if (std::isnan(f(j, 3))) continue;  // the diffuse start
    weighted += f(j, 2) * f(j, 2) / f(j, 3);
    log_f += std::log(f(j, 3));
    ++m;
  }
  Likelihood out;
  out.noise_var = weighted / static_cast<double>(m);
  if (!(out.noise_var > 0.0)) return out;  // a series the model fits exactly: no likelihood
  const double md = static_cast<double>(m);
  out.log_likelihood = -0.5 * (md * std::log(2.0 * std::numbers::pi * out.noise_var) + md + log_f);
  return out;
}

Baseline FitKalman(Method method, const Eigen::Ref<const Eigen::VectorXd>& y) {
  const bool trend = method == Method::kKalmanTrend;
  double best_l = 0.0, best_s = 0.0;
  Likelihood best;
  auto consider = [&](double log_l, double log_s) {
    const Likelihood l =
        ConcentratedLikelihood(y, trend, std::pow(10.0, log_l), std::pow(10.0, log_s));
    if (l.log_likelihood > best.log_likelihood) {
      best = l;
      best_l = log_l;
      best_s = log_s;
    }
  };
  // Whole decades, then eighths of a decade within one of the best.
  const int slope_lo = trend ? -20 : 0, slope_hi = trend ? -2 : 0;
  for (int l = -16; l <= 2; ++l) {
    for (int s = slope_lo; s <= slope_hi; ++s) consider(l, s);
  }
  const double centre_l = best_l, centre_s = best_s;
  for (int i = -8; i <= 8; ++i) {
    for (int k = trend ? -8 : 0; k <= (trend ? 8 : 0); ++k) {
      if (i == 0 && k == 0) continue;
      consider(centre_l + i / 8.0, centre_s + k / 8.0);
    }
  }
  if (!std::isfinite(best.log_likelihood)) {
    throw DataError(std::string(ToString(method)) +
                    ": the training block leaves no innovation variance to estimate (a constant or "
                    "exactly linear series)");
  }
  Baseline b;
  b.method = method;
  b.noise_var = best.noise_var;
  b.level_var = std::pow(10.0, best_l) * best.noise_var;
  b.slope_var = trend ? std::pow(10.0, best_s) * best.noise_var : 0.0;
  b.criterion = best.log_likelihood;
  return b;
}

}  // namespace

bool IsBaseline(Method method) {
  switch (method) {
    case Method::kNone:
    case Method::kConstant:
    case Method::kPersistence:
    case Method::kTrailingMean:
    case Method::kExpSmoothing:
    case Method::kKalmanLevel:
    case Method::kKalmanTrend:
      return true;
    default:
      return false;
  }
}

Eigen::MatrixXd KalmanFilterStates(const Eigen::Ref<const Eigen::VectorXd>& y, bool trend,
                                   double level_var, double slope_var, double noise_var) {
  const Eigen::Index n = y.size();
  Eigen::MatrixXd out(n, 4);
  out.col(2).setConstant(kNaN);
  out.col(3).setConstant(kNaN);
  if (n == 0) return out;
  // Exact diffuse start (Durbin & Koopman 2012, 2.9 and 5.6): after y[0] the level is y[0] with
  // variance r; the trend model's slope needs y[1] too: level y[1], slope y[1] - y[0], covariance
  // [[r, r], [r, 2r + q_level + q_slope]]. Before that its slope is unknown, written as 0.
  Eigen::Vector2d a(y[0], 0.0);
  Eigen::Matrix2d p = Eigen::Matrix2d::Zero();
  p(0, 0) = noise_var;
  out.row(0).head(2) = a.transpose();
  Eigen::Index start = 1;
  if (trend && n > 1) {
    a << y[1], y[1] - y[0];
    p << noise_var, noise_var, noise_var, 2.0 * noise_var + level_var + slope_var;
    out.row(1).head(2) = a.transpose();
    start = 2;
  }
  for (Eigen::Index j = start; j < n; ++j) {
    // Predict: level += slope, both step by their variances.
    const Eigen::Vector2d a_pred(a[0] + a[1], a[1]);
    Eigen::Matrix2d p_pred;
    p_pred(0, 0) = p(0, 0) + 2.0 * p(0, 1) + p(1, 1) + level_var;
    p_pred(0, 1) = p(0, 1) + p(1, 1);
    p_pred(1, 0) = p_pred(0, 1);
    p_pred(1, 1) = p(1, 1) + slope_var;
    // Update with y[j].
    const double v = y[j] - a_pred[0];
    const double f = p_pred(0, 0) + noise_var;
    const Eigen::Vector2d k = p_pred.col(0) / f;
    a = a_pred + k * v;
    p = p_pred - k * k.transpose() * f;
    out(j, 0) = a[0];
    out(j, 1) = a[1];
    out(j, 2) = v;
    out(j, 3) = f;
  }
  return out;
}

void Baseline::Validate() const {
  if (!IsBaseline(method)) {
    throw DataError("baseline: method " + std::string(ToString(method)) + " is not a baseline");
  }
  auto fail = [](const char* field, double value, const std::string& rule) {
    throw DataError(Format("baseline %s = %.17g: must be %s", field, value, rule.c_str()));
  };
  if (method == Method::kConstant && !std::isfinite(constant)) fail("constant", constant, "finite");
  if (method == Method::kTrailingMean && (window < 1 || window > kLongestWindow)) {
    fail("window", window, "an integer in [1, " + std::to_string(kLongestWindow) + "]");
  }
  if (method == Method::kExpSmoothing && !(alpha > 0.0 && alpha <= 1.0)) {
    fail("alpha", alpha, "in (0, 1]");
  }
  if (IsKalman(method)) {
    if (!(noise_var > 0.0 && std::isfinite(noise_var))) fail("noise_var", noise_var, "> 0, finite");
    if (!(level_var >= 0.0 && std::isfinite(level_var)))
      fail("level_var", level_var, ">= 0, finite");
    if (!(slope_var >= 0.0 && std::isfinite(slope_var)) ||
        (method == Method::kKalmanLevel && slope_var != 0.0)) {
      fail("slope_var", slope_var,
           method == Method::kKalmanLevel ? "0 for kalman-level" : ">= 0, finite");
    }
  }
}

std::string Baseline::Summary() const {
  switch (method) {
    case Method::kNone:
      return "zero estimate (doing nothing)";
    case Method::kConstant:
      return Format("training mean %.6g", constant);
    case Method::kPersistence:
      return "the last sample";
    case Method::kTrailingMean:
      return Format("mean of the last %d samples (one-step validation RMSE %.4g)", window,
                    criterion);
    case Method::kExpSmoothing:
      return Format("exponential smoothing, alpha %.4g (one-step validation RMSE %.4g)", alpha,
                    criterion);
    case Method::kKalmanLevel:
      return Format(
          "Kalman local level: level step sd %.4g, noise sd %.4g (maximum likelihood, "
          "log-likelihood %.6g)",
          std::sqrt(level_var), std::sqrt(noise_var), criterion);
    case Method::kKalmanTrend:
      return Format(
          "Kalman local linear trend: level step sd %.4g, slope step sd %.4g, noise sd %.4g "
          "(maximum likelihood, log-likelihood %.6g)",
          std::sqrt(level_var), std::sqrt(slope_var), std::sqrt(noise_var), criterion);
    default:
      return "";
  }
}

Baseline FitBaseline(Method method, const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (!IsBaseline(method)) {
    throw UsageError("method " + std::string(ToString(method)) + " is not a baseline");
  }
  RequireFiniteSignal("target", y, 32);
  const Eigen::Index n = y.size();
  Baseline b;
  b.method = method;
  switch (method) {
    case Method::kConstant:
      b.constant = y.mean();
      break;
    case Method::kTrailingMean: {
      std::vector<int> windows;
      for (int k = 0; k <= 16; ++k) {
        const int w = static_cast<int>(std::lround(16.0 * std::pow(2.0, k / 2.0)));
        if (w > n && k > 0) break;
        windows.push_back(w);
      }
      b.window = BestOnGrid(windows, [&](int w) { return OneStepRmse(y, TrailingMeans(y, n, w)); },
                            b.criterion);
      break;
    }
    case Method::kExpSmoothing: {
      std::vector<double> alphas;
      for (int k = 0; k <= 28; ++k) alphas.push_back(std::pow(2.0, -k / 2.0));
      b.alpha = BestOnGrid(
          alphas, [&](double alpha) { return OneStepRmse(y, SmoothedLevels(y, n, alpha)); },
          b.criterion);
      break;
    }
    case Method::kKalmanLevel:
    case Method::kKalmanTrend:
      b = FitKalman(method, y);
      break;
    default:
      break;
  }
  b.Validate();
  return b;
}

Eigen::VectorXd ForecastBaseline(const Baseline& baseline,
                                 const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index first,
                                 Eigen::Index count, int horizon) {
  baseline.Validate();
  const Eigen::Index first_origin = first - horizon + 1;
  const Eigen::Index end = first_origin + count - 1;  // the last origin: reads y[0 .. end - 1]
  if (horizon < 1 || count < 0 || first_origin < 1 || end > y.size()) {
    throw DataError(Format(
        "%s forecast of samples %lld..%lld %d step(s) ahead needs samples 1..%lld before them, "
        "%lld given",
        std::string(ToString(baseline.method)).c_str(), static_cast<long long>(first + 1),
        static_cast<long long>(first + count), horizon,
        static_cast<long long>(std::max<Eigen::Index>(1, end)), static_cast<long long>(y.size())));
  }
  if (count == 0) return Eigen::VectorXd(0);
  RequireFiniteSignal("target", y.head(end), 1);
  // after[j]: the forecast made after sample j (origin j + 1), one step ahead.
  Eigen::VectorXd after;
  Eigen::VectorXd slope;  // kalman-trend: the slope after sample j
  switch (baseline.method) {
    case Method::kNone:
      return Eigen::VectorXd::Zero(count);
    case Method::kConstant:
      return Eigen::VectorXd::Constant(count, baseline.constant);
    case Method::kPersistence:
      after = y.head(end);
      break;
    case Method::kTrailingMean:
      after = TrailingMeans(y, end, baseline.window);
      break;
    case Method::kExpSmoothing:
      after = SmoothedLevels(y, end, baseline.alpha);
      break;
    default: {
      const bool trend = baseline.method == Method::kKalmanTrend;
      const Eigen::MatrixXd f = KalmanFilterStates(y.head(end), trend, baseline.level_var,
                                                   baseline.slope_var, baseline.noise_var);
      after = f.col(0);
      if (trend) slope = f.col(1);
    }
  }
  Eigen::VectorXd out = after.segment(first_origin - 1, count);
  if (slope.size() > 0) {
    out += static_cast<double>(horizon) * slope.segment(first_origin - 1, count);
  }
  return out;
}

}  // namespace gyrodrift::drift
