// The thermal models in a model file (model_json.h): their identification options, the fitted
// regression with its calibration report, and the form an autopilot runs.
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "model_json.h"

namespace gyrodrift::io::internal {

json ThermalOptionsJson(const drift::ThermalModelOptions& t) {
  return {{"shortest_tau_s", Number(t.shortest_tau_s)},
          {"longest_tau_s", Number(t.longest_tau_s)},
          {"taus_per_octave", t.taus_per_octave},
          {"longest_tau_share", Number(t.longest_tau_share)},
          {"max_states", t.max_states},
          {"state_order", t.state_order},
          {"max_power", t.max_power},
          {"folds", t.folds},
          {"folds_at_regimes", t.folds_at_regimes},
          {"ramp_rate_k_per_min", Number(t.ramp_rate_k_per_min)},
          {"hysteresis", drift::ToString(t.hysteresis)},
          {"hysteresis_widths_k", Numbers(t.hysteresis_widths_k)},
          {"max_condition", Number(t.max_condition)},
          {"standard_errors", Number(t.standard_errors)}};
}

namespace {

json AutopilotJson(const drift::AutopilotForm& a) {
  if (!a.fitted()) return nullptr;
  return {{"degree", a.degree},
          {"tref_c", Number(a.tref_c)},
          {"tmin_c", Number(a.tmin_c)},
          {"tmax_c", Number(a.tmax_c)},
          {"coefficients", Numbers({a.coefficients.begin(), a.coefficients.end()})},
          {"share_kept", Number(a.share_kept)}};
}

drift::AutopilotForm ReadAutopilot(const Node& n) {
  drift::AutopilotForm a;
  if (n.IsNull()) return a;
  a.degree = static_cast<int>(n["degree"].Int(0, 3));
  a.tref_c = n["tref_c"].Double();
  a.tmin_c = n["tmin_c"].Double();
  a.tmax_c = n["tmax_c"].Double();
  const std::vector<double> c = n["coefficients"].Doubles();
  if (c.size() != a.coefficients.size()) n["coefficients"].Fail("must hold 4 numbers");
  std::copy(c.begin(), c.end(), a.coefficients.begin());
  a.share_kept = n["share_kept"].Double();
  return a;
}

}  // namespace

json ThermalJson(const drift::ThermalRegression& t) {
  json states = json::array();
  for (const auto& s : t.states) {
    states.push_back({{"channel", s.channel},
                      {"tau_s", Number(s.tau_s)},
                      {"level_range", Numbers({s.level_min, s.level_max})},
                      {"rate_range", Numbers({s.rate_min, s.rate_max})},
                      {"rate_beyond", Number(s.rate_beyond)}});
  }
  json static_range = json::array();
  for (size_t c = 0; c < t.static_min.size(); ++c) {
    static_range.push_back(Numbers({t.static_min[c], t.static_max[c]}));
  }
  const drift::CalibrationReport& r = t.report;
  json j = {{"rate_hz", Number(t.rate_hz)},
          {"order", t.order},
          {"max_power", t.max_power},
          {"centre_c", Numbers(t.centre_c)},
          {"scale_k", Numbers(t.scale_k)},
          {"static_power", t.static_power},
          {"static_range", std::move(static_range)},
          {"states", std::move(states)},
          {"hysteresis", t.has_hysteresis() ? json{{"state", t.hysteresis_state},
                                                   {"width_k", Number(t.hysteresis_width_k)}}
                                            : json(nullptr)},
          {"regressors", t.RegressorNames()},
          {"coefficients", Array(t.coefficients)},
          {"covariance", Array(t.covariance)},
          {"cv_slow_sd", Number(t.cv_slow_sd)},
          {"correction", t.correction ? LearnerJson(*t.correction) : json(nullptr)},
          {"autopilot", AutopilotJson(t.autopilot)},
          {"report",
           {{"duration_s", Number(r.duration_s)},
            {"span_k", Numbers(r.span_k)},
            {"max_heating_k_per_min", Number(r.max_heating_k_per_min)},
            {"max_cooling_k_per_min", Number(r.max_cooling_k_per_min)},
            {"ramps", r.ramps},
            {"dwells", r.dwells},
            {"folds", r.folds},
            {"cv_rmse", Number(r.cv_rmse)},
            {"cv_rmse_constant", Number(r.cv_rmse_constant)},
            {"skill", Number(r.skill)},
            {"condition", Number(r.condition)},
            {"prior_samples", Number(r.prior_samples)},
            {"level", r.level},
            {"best_level", r.best_level},
            {"regime_folds", r.regime_folds},
            {"range_folds", r.range_folds},
            {"held_out_rmse", Number(r.held_out_rmse)},
            {"held_out_rmse_constant", Number(r.held_out_rmse_constant)},
            {"held_out_rmse_static", Number(r.held_out_rmse_static)},
            {"held_out_rmse_best", Number(r.held_out_rmse_best)},
            {"regime_rmse", Number(r.regime_rmse)},
            {"regime_rmse_constant", Number(r.regime_rmse_constant)},
            {"regime_rmse_static", Number(r.regime_rmse_static)},
            {"advice", r.advice},
            {"nonlinear_units", r.nonlinear_units},
            {"hysteresis_tried", r.hysteresis_tried},
            {"nonlinear_ridge_c", Number(r.nonlinear_ridge_c)},
            {"cv_rmse_nonlinear", Number(r.cv_rmse_nonlinear)},
            {"warnings", r.warnings}}}};
  // Written only for a fit on several records, so a one-record model's file is unchanged.
  if (r.records > 1) j["report"]["records"] = r.records;
  return j;
}

drift::ThermalModelOptions ReadThermalOptions(const Node& n) {
  drift::ThermalModelOptions t;
  t.shortest_tau_s = n["shortest_tau_s"].Double();
  t.longest_tau_s = n["longest_tau_s"].Double();
  t.taus_per_octave = n["taus_per_octave"].Int();
  t.longest_tau_share = n["longest_tau_share"].Double();
  t.max_states = n["max_states"].Int();
  t.state_order = n["state_order"].Int();
  t.max_power = n["max_power"].Int();
  t.folds = n["folds"].Int();
  t.folds_at_regimes = n["folds_at_regimes"].Bool();
  t.ramp_rate_k_per_min = n["ramp_rate_k_per_min"].Double();
  // Files before version 5 were identified without the hysteresis term.
  t.hysteresis = n.raw().contains("hysteresis")
                     ? n["hysteresis"].Enum(drift::HysteresisTermFromString)
                     : drift::HysteresisTerm::kOff;
  if (n.raw().contains("hysteresis_widths_k")) {
    t.hysteresis_widths_k = n["hysteresis_widths_k"].Doubles();
  }
  // Files before version 7 chose the richest structure of least error, without these rules.
  if (n.raw().contains("max_condition")) {
    t.max_condition = n["max_condition"].Double();
    t.standard_errors = n["standard_errors"].Double();
  }
  return t;
}

namespace {

// The calibration report of a thermal model (fields of older formats keep their defaults).
drift::CalibrationReport ReadReport(const Node& r) {
  drift::CalibrationReport report;
  report.duration_s = r["duration_s"].Double();
  report.records = r.raw().contains("records") ? r["records"].Int(2, 1000000000) : 1;
  report.span_k = r["span_k"].Doubles();
  report.max_heating_k_per_min = r["max_heating_k_per_min"].Double();
  report.max_cooling_k_per_min = r["max_cooling_k_per_min"].Double();
  report.ramps = r["ramps"].Int();
  report.dwells = r["dwells"].Int();
  report.folds = r["folds"].Int();
  report.cv_rmse = r["cv_rmse"].Double();
  report.cv_rmse_constant = r["cv_rmse_constant"].Double();
  report.skill = r["skill"].Double();
  report.condition = r["condition"].Double();
  report.prior_samples = r.raw().contains("prior_samples") ? r["prior_samples"].Double() : 0.0;
  if (r.raw().contains("level")) {  // version 7
    report.level = static_cast<int>(r["level"].Int(0, drift::CalibrationReport::kHysteresis));
    report.best_level =
        static_cast<int>(r["best_level"].Int(0, drift::CalibrationReport::kHysteresis));
    report.regime_folds = static_cast<int>(r["regime_folds"].Int(0, 1000000));
    report.range_folds = static_cast<int>(r["range_folds"].Int(0, 2));
    report.held_out_rmse = r["held_out_rmse"].Double();
    report.held_out_rmse_constant = r["held_out_rmse_constant"].Double();
    report.held_out_rmse_static = r["held_out_rmse_static"].Double();
    report.held_out_rmse_best = r["held_out_rmse_best"].Double();
    report.regime_rmse = r["regime_rmse"].Double();
    report.regime_rmse_constant = r["regime_rmse_constant"].Double();
    report.regime_rmse_static = r["regime_rmse_static"].Double();
    for (const Node& a : r["advice"].Items()) report.advice.push_back(a.String());
  }
  report.nonlinear_units = r["nonlinear_units"].Int(0, 100000);
  report.hysteresis_tried = r.raw().contains("hysteresis_tried") && r["hysteresis_tried"].Bool();
  report.nonlinear_ridge_c = r["nonlinear_ridge_c"].Double();
  report.cv_rmse_nonlinear = r["cv_rmse_nonlinear"].Double();
  for (const Node& w : r["warnings"].Items()) report.warnings.push_back(w.String());
  return report;
}

}  // namespace

std::shared_ptr<const drift::ThermalRegression> ReadThermal(const Node& n) {
  auto t = std::make_shared<drift::ThermalRegression>();
  t->rate_hz = n["rate_hz"].Double();
  t->order = n["order"].Int(1, 4);
  t->max_power = n["max_power"].Int(1, 3);
  t->centre_c = n["centre_c"].Doubles();
  t->scale_k = n["scale_k"].Doubles();
  auto pair = [](const Node& node) {
    const std::vector<double> range = node.Doubles();
    if (range.size() != 2) node.Fail("must hold [min, max]");
    return std::pair{range[0], range[1]};
  };
  if (n.raw().contains("static_power")) {
    for (const Node& p : n["static_power"].Items()) {
      t->static_power.push_back(static_cast<int>(p.Int(0, 3)));
    }
    for (const Node& r : n["static_range"].Items()) {
      const auto [lo, hi] = pair(r);
      t->static_min.push_back(lo);
      t->static_max.push_back(hi);
    }
  } else {  // before version 7: a linear term per channel, unbounded
    for (const Node& b : n["linear"].Items()) {
      t->static_power.push_back(b.Bool() ? 1 : 0);
      t->static_min.push_back(-std::numeric_limits<double>::infinity());
      t->static_max.push_back(std::numeric_limits<double>::infinity());
    }
  }
  for (const Node& s : n["states"].Items()) {
    drift::ThermalState state{static_cast<int>(s["channel"].Int(0, 1024)), s["tau_s"].Double()};
    std::tie(state.level_min, state.level_max) = pair(s["level_range"]);
    // Before version 7 the rates ran unheld.
    if (s.raw().contains("rate_range")) std::tie(state.rate_min, state.rate_max) = pair(s["rate_range"]);
    // Before version 9 a rate was held at the edges of its range.
    if (s.raw().contains("rate_beyond")) state.rate_beyond = s["rate_beyond"].Double();
    t->states.push_back(state);
  }
  if (n.raw().contains("hysteresis") && !n["hysteresis"].IsNull()) {
    const Node h = n["hysteresis"];
    t->hysteresis_state = static_cast<int>(h["state"].Int(0, 1024));
    t->hysteresis_width_k = h["width_k"].Double();
  }
  const Eigen::MatrixXd coefficients = n["coefficients"].Matrix();
  if (coefficients.cols() != 1) n["coefficients"].Fail("must be a column (cols = 1)");
  t->coefficients = coefficients.col(0);
  t->covariance = n["covariance"].Matrix();
  t->cv_slow_sd = n["cv_slow_sd"].Double();
  t->report = ReadReport(n["report"]);
  if (n.raw().contains("autopilot")) t->autopilot = ReadAutopilot(n["autopilot"]);
  if (!n["correction"].IsNull()) t->correction = ReadLearner(n["correction"], "correction");
  try {
    t->Validate();
  } catch (const DataError& e) {
    n.Fail(std::string("does not rebuild: ") + e.what());
  }
  if (n["regressors"].raw() != json(t->RegressorNames())) {
    n["regressors"].Fail("does not match the states and channels stored");
  }
  return t;
}

}  // namespace gyrodrift::io::internal
