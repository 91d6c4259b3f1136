// The calibration run's regimes and sufficiency: Segments, the report's description, warnings,
// advice and summary (thermal_report.h, thermal_model.h).
#include "thermal_report.h"

#include <algorithm>
#include <cmath>

#include "gyrodrift/drift/features.h"

namespace gyrodrift::drift {
namespace {

constexpr double kRateSmoothingS = 60.0;  // smoothing of the rate that tells ramps from dwells
constexpr double kShortestSegmentS = 300.0;
constexpr double kShortestDwellS = 600.0;
// Calibration sufficiency: warnings below these (docs/drift.md 4.5, 4.8).
constexpr double kLeastSkill = 0.2;
// Above ThermalModelOptions::max_condition's default (1e8): it warns a caller who raised that.
constexpr double kLargestCondition = 1e10;
// Shorter than this, a log is not a calibration run: no regime can be held out.
constexpr double kShortestCalibrationS = 3600.0;

// Adds v to `values` unless one of them is within `step` of it (a factor with `ratio`).
void AddDistinct(double v, double step, bool ratio, std::vector<double>& values) {
  for (double u : values) {
    if (ratio ? std::max(u, v) < step * std::min(u, v) : std::abs(u - v) < step) return;
  }
  values.push_back(v);
}

}  // namespace

namespace internal {

std::vector<ThermalSegment> RecordSegments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                           double rate_hz, double ramp_rate_k_per_min,
                                           const std::vector<Eigen::Index>& record_starts) {
  std::vector<ThermalSegment> all;
  ForEachRecord(temperature_c.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
    for (ThermalSegment s :
         Segments(temperature_c.segment(begin, length), rate_hz, ramp_rate_k_per_min)) {
      s.begin += begin;
      s.end += begin;
      all.push_back(s);
    }
  });
  return all;
}

RunRegimes DescribeRun(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c, double rate_hz,
                       const std::vector<ThermalSegment>& segments,
                       const std::vector<Eigen::Index>& record_starts, CalibrationReport& report) {
  const double dt = 1.0 / rate_hz;
  for (Eigen::Index c = 0; c < temperatures_c.cols(); ++c) {
    report.span_k.push_back(temperatures_c.col(c).maxCoeff() - temperatures_c.col(c).minCoeff());
  }
  // Channel 0's 60-s smoothed rate, K/min, restarting with every record, and its widest span
  // within one record.
  const auto t0 = temperatures_c.col(0);
  Eigen::VectorXd rate(t0.size());
  RunRegimes regimes;
  ForEachRecord(t0.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
    const auto t = t0.segment(begin, length);
    Eigen::VectorXd smooth(length);
    FirstOrderLag(t, kRateSmoothingS, dt, smooth);
    rate.segment(begin, length) = (t - smooth) * (60.0 / kRateSmoothingS);
    regimes.widest_record_k = std::max(regimes.widest_record_k, t.maxCoeff() - t.minCoeff());
  });
  if (rate.size() > 0) {
    report.max_heating_k_per_min = std::max(0.0, rate.maxCoeff());
    report.max_cooling_k_per_min = std::max(0.0, -rate.minCoeff());
  }
  // Every row counts, made-up ones included: the time the temperature spent, which a duty-cycled
  // log's bursts sample (counting logged rows only would take every such log for a step).
  const double low = t0.minCoeff() + 0.5 * (1.0 - kMidRangeShare) * report.span_k[0];
  const double high = low + kMidRangeShare * report.span_k[0];
  regimes.mid_range_s =
      static_cast<double>(((t0.array() > low) && (t0.array() < high)).count()) * dt;
  // A ramp's rate is its steepest (the programme's; a sensor behind a case approaches the end of
  // a ramp slowly), a dwell's level its mean.
  const double level_step = std::max(kDistinctLevelK, kDistinctLevelShare * report.span_k[0]);
  for (const ThermalSegment& s : segments) {
    const double length_s = static_cast<double>(s.end - s.begin) * dt;
    if (s.ramp) {
      ++report.ramps;
      const auto r = rate.segment(s.begin, s.end - s.begin);
      const bool heating = t0[s.end - 1] > t0[s.begin];
      AddDistinct(heating ? r.maxCoeff() : -r.minCoeff(), kDistinctRateFactor, /*ratio=*/true,
                  heating ? regimes.heating_k_per_min : regimes.cooling_k_per_min);
    } else if (length_s >= kShortestDwellS) {
      ++report.dwells;
      AddDistinct(t0.segment(s.begin, s.end - s.begin).mean(), level_step, /*ratio=*/false,
                  regimes.dwell_levels_c);
    }
  }
  return regimes;
}

namespace {

// What the calibration run lacks (duration, span, ramps both ways, dwells, regimes, time in the
// middle of its range), in that order.
void AddRunWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                    const RunRegimes& regimes, CalibrationReport& report) {
  auto& w = report.warnings;
  auto& advice = report.advice;
  if (report.duration_s < kShortestCalibrationS) {
    w.push_back(
        Format("a log of %.3g min is not a calibration run: nothing of its thermal "
               "response can be held out and checked",
               report.duration_s / 60.0));
    advice.push_back(
        "log a calibration run of at least 8 h: ramps up and down at 0.5-2 K/min "
        "and dwells of 30 min or more at 3 or more temperatures");
  }
  const int channels = model.channels();
  for (int c = 0; c < channels; ++c) {
    if (report.span_k[static_cast<size_t>(c)] < kShortestSpanK) {
      w.push_back(Format("temperature %sspans only %.3g K: the model is not identified beyond it",
                         channels > 1 ? Format("T%d ", c + 1).c_str() : "",
                         report.span_k[static_cast<size_t>(c)]));
      advice.push_back(
          Format("narrow range: cover at least %.0f K, ideally the whole operating "
                 "range",
                 kShortestSpanK));
    }
  }
  if (report.max_heating_k_per_min < 2.0 * options.ramp_rate_k_per_min) {
    w.push_back("no heating ramp: the response to rising temperature is not identified");
    advice.push_back("no heating: add a ramp up of at least 20 K at 0.5-2 K/min");
  }
  if (report.max_cooling_k_per_min < 2.0 * options.ramp_rate_k_per_min) {
    w.push_back("no cooling ramp: the response to falling temperature is not identified");
    advice.push_back("no cooling: add a ramp down of at least 20 K at 0.5-2 K/min");
  }
  if (report.dwells == 0) {
    w.push_back(
        "no dwell of 10 min or more: the level response cannot be told from the rate response");
  }
  const int levels = static_cast<int>(regimes.dwell_levels_c.size());
  if (levels < 3) {
    advice.push_back(
        Format("dwells at %d temperature%s: hold 30 min or more at 3 or more temperatures across "
               "the range",
               levels, levels == 1 ? "" : "s"));
  }
  const std::pair<const std::vector<double>*, const char*> directions[] = {
      {&regimes.heating_k_per_min, "heating"}, {&regimes.cooling_k_per_min, "cooling"}};
  for (const auto& [rates, name] : directions) {
    if (rates->size() != 1) continue;
    advice.push_back(
        Format("%s at one rate (%.2g K/min): add a %s ramp at about half or twice "
               "it, so that the rate terms are told from the level",
               name, rates->front(), name));
  }
  if (report.ramps + report.dwells < 3) {
    w.push_back("fewer than 3 thermal regimes (ramps and dwells): nothing new to hold out");
  }
  if (model.max_power < options.max_power) {
    w.push_back(Format(
        "the run spent %.3g min in the middle half of its temperature range (%.0f min show a "
        "curve): the levels enter linearly, a line between the temperatures it held",
        regimes.mid_range_s / 60.0, kCurveSupportS / 60.0));
    advice.push_back(Format(
        "mid-range: dwell %.0f min or more in the middle of the range, or ramp across it at %.2g "
        "K/min or slower",
        kCurveSupportS / 60.0, kMidRangeShare * report.span_k[0] / (kCurveSupportS / 60.0)));
  }
}

// What limits the model the run gave: how far its states can lag, how little it beats a constant
// bias, what the run's temperatures could not support, how collinear its regressors are.
void AddModelWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                      const SearchResult& search, CalibrationReport& report) {
  const bool fell_back_to_constant = search.fell_back_to_constant;
  auto& w = report.warnings;
  auto& advice = report.advice;
  // The slowest candidate state's mean delay: order x tau.
  const std::vector<double> grid = options.Grid(report.duration_s);
  const double longest_delay = grid.empty() ? 0.0 : options.state_order * grid.back();
  if (longest_delay < kSlowLagS) {
    w.push_back(Format(
        "thermal states could lag the sensor by at most %.0f s (time constants up to %g of the "
        "run): a gyro whose coil lags its sensor by more needs a longer calibration run",
        longest_delay, options.longest_tau_share));
    const double needed_h = options.HoursReachingLag(kSlowLagS);
    advice.push_back(
        Format("short run: %.3g h lets states lag by %.0f s at most; %g h reaches %.0f s",
               report.duration_s / 3600.0, longest_delay, needed_h,
               options.state_order * options.Grid(needed_h * 3600.0).back()));
  }
  double slowest = 0.0;
  for (const ThermalState& s : model.states) slowest = std::max(slowest, s.tau_s);
  if (slowest > 0.0 && report.duration_s < 8.0 * slowest) {
    w.push_back(
        Format("the run is shorter than 8 times the slowest chosen time constant (%g s)", slowest));
  }
  if (fell_back_to_constant) {
    w.push_back(Format(
        "no temperature dependence beats a constant bias on held-out data (held-out RMSE of the "
        "best structure %.4g, of the constant %.4g): the model is the constant bias",
        report.held_out_rmse_best, report.held_out_rmse_constant));
  } else if (!std::isnan(report.skill) && report.skill < kLeastSkill) {
    w.push_back(Format(
        "cross-validation confirms little temperature dependence (skill %.1f %%): the estimate "
        "is close to a constant bias",
        100.0 * report.skill));
  }
  if (search.best_unsupported_score < search.best_score) {
    w.push_back(Format(
        "the structure of least held-out error (RMSE %.4g, against %.4g of the best kept) was left "
        "out: its steady-state drift leaves the band the run showed, a curve between the logged "
        "temperatures that the run cannot support",
        std::sqrt(search.best_unsupported_score), std::sqrt(search.best_score)));
    // A run that never sat mid-range has the mid-range advice already.
    if (model.max_power == options.max_power) {
      advice.push_back(
          "temperatures between the logged ones: log the range between them (a ramp across it, or "
          "a dwell in it)");
    }
  }
  if (report.regime_rmse > report.regime_rmse_constant && report.level > 0) {
    w.push_back(Format(
        "on held-out regimes and range ends the model does worse than a constant bias (RMSE %.4g "
        "against %.4g): the run cannot confirm it beyond what it spans; see the advice",
        report.regime_rmse, report.regime_rmse_constant));
  }
  if (report.condition > kLargestCondition) {
    w.push_back(
        Format("the chosen regressors are nearly collinear (condition %.2g)", report.condition));
  }
}

}  // namespace

void AddWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                 const SearchResult& search, const RunRegimes& regimes, CalibrationReport& report) {
  AddRunWarnings(model, options, regimes, report);
  AddModelWarnings(model, options, search, report);
}

}  // namespace internal

std::vector<ThermalSegment> Segments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                     double rate_hz, double ramp_rate_k_per_min) {
  const Eigen::Index n = temperature_c.size();
  std::vector<ThermalSegment> segments;
  if (n == 0) return segments;
  Eigen::VectorXd smooth(n);
  FirstOrderLag(temperature_c, kRateSmoothingS, 1.0 / rate_hz, smooth);
  const double threshold = ramp_rate_k_per_min / 60.0 * kRateSmoothingS;  // K of lag
  const Eigen::Index shortest =
      std::max<Eigen::Index>(1, static_cast<Eigen::Index>(kShortestSegmentS * rate_hz));
  for (Eigen::Index t = 0; t < n; ++t) {
    const bool ramp = std::abs(temperature_c[t] - smooth[t]) > threshold;
    if (!segments.empty() && segments.back().ramp == ramp) {
      segments.back().end = t + 1;
    } else {
      segments.push_back({t, t + 1, ramp});
    }
  }
  // Merge short stretches into the one before (the first into the one after), then join
  // neighbours of one kind.
  std::vector<ThermalSegment> merged;
  for (const ThermalSegment& s : segments) {
    if (!merged.empty() && (s.end - s.begin < shortest || merged.back().ramp == s.ramp)) {
      merged.back().end = s.end;
    } else if (!merged.empty() && merged.back().end - merged.back().begin < shortest) {
      merged.back().end = s.end;
      merged.back().ramp = s.ramp;
    } else {
      merged.push_back(s);
    }
  }
  return merged;
}

std::string CalibrationReport::Summary() const {
  using internal::Format;
  static constexpr const char* kLevelNames[] = {"the constant",   "static powers of T",
                                                "a lagged level", "one lag state",
                                                "two lag states", "a hysteresis term"};
  std::string span;
  for (size_t c = 0; c < span_k.size(); ++c) span += Format("%s%.3g", c ? "/" : "", span_k[c]);
  const std::string skill_text = std::isnan(skill)
                                     ? std::string("skill not measured (run under 40 min)")
                                     : Format("skill %.1f %% of the slow drift", 100.0 * skill);
  auto gain = [](double rmse, double reference) {
    return reference > 0.0 ? Format("%+.1f %%", 100.0 * (1.0 - rmse / reference))
                           : std::string("n/a");
  };
  return Format(
             "%.3g h%s, span %s K, rates +%.2g/-%.2g K/min, %d ramps, %d dwells, %d time folds, %d "
             "regime folds, %d range folds; structure: %s (best held-out: %s); held-out RMSE %.4g "
             "(against the constant %s, the static polynomial %s; on held-out regimes %s and %s); "
             "cross-validated RMSE %.4g (constant %.4g), %s, condition %.2g; hysteresis term %s",
             duration_s / 3600.0, records > 1 ? Format(" in %d records", records).c_str() : "",
             span.c_str(), max_heating_k_per_min, max_cooling_k_per_min, ramps, dwells, folds,
             regime_folds, range_folds, kLevelNames[std::clamp(level, 0, 5)],
             kLevelNames[std::clamp(best_level, 0, 5)], held_out_rmse,
             gain(held_out_rmse, held_out_rmse_constant).c_str(),
             gain(held_out_rmse, held_out_rmse_static).c_str(),
             gain(regime_rmse, regime_rmse_constant).c_str(),
             gain(regime_rmse, regime_rmse_static).c_str(), cv_rmse, cv_rmse_constant,
             skill_text.c_str(), condition, hysteresis_tried ? "tried" : "not tried") +
         (prior_samples > 0.0 ? Format("; coefficients shrunk by a ridge worth %g logged samples "
                                       "(most rows made up across gaps)",
                                       prior_samples)
                              : std::string()) +
         (std::isnan(cv_rmse_nonlinear) ? std::string()
          : nonlinear_units > 0
              ? Format("; nonlinear correction %d units, C %g (cross-validated RMSE %.4g)",
                       nonlinear_units, nonlinear_ridge_c, cv_rmse_nonlinear)
              : Format("; no nonlinear correction (best cross-validated RMSE %.4g)",
                       cv_rmse_nonlinear));
}

}  // namespace gyrodrift::drift
