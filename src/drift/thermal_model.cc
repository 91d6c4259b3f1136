#include "gyrodrift/drift/thermal_model.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "../common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "../common/format.h"
#include "gyrodrift/drift/records.h"
#include "thermal_columns.h"

namespace gyrodrift::drift {
namespace {

using internal::HysteresisColumns;
using internal::StateColumns;
using internal::StaticColumns;

constexpr size_t kMostHysteresisWidths = 8;

constexpr gyrodrift::internal::EnumNames<HysteresisTerm, 3> kHysteresisTerms{{
    {HysteresisTerm::kAuto, "auto"}, {HysteresisTerm::kOn, "on"}, {HysteresisTerm::kOff, "off"}}};

}  // namespace

void ThermalModelOptions::Validate() const {
  RequireInRange("shortest_tau_s", shortest_tau_s, 1.0, 1e6);
  RequireInRange("longest_tau_s", longest_tau_s, shortest_tau_s, 1e6);
  if (taus_per_octave < 1 || taus_per_octave > 8) {
    ThrowOption("taus_per_octave", std::to_string(taus_per_octave), "an integer in [1, 8]");
  }
  if (!(longest_tau_share > 0.0 && longest_tau_share <= 1.0)) {
    ThrowOption("longest_tau_share", FormatValue(longest_tau_share), "in (0, 1]");
  }
  if (max_states < 0 || max_states > 4) {
    ThrowOption("max_states", std::to_string(max_states), "an integer in [0, 4]");
  }
  if (state_order < 1 || state_order > 4) {
    ThrowOption("state_order", std::to_string(state_order), "an integer in [1, 4]");
  }
  if (max_power < 1 || max_power > 3) {
    ThrowOption("max_power", std::to_string(max_power), "an integer in [1, 3]");
  }
  if (folds < 2 || folds > 64) ThrowOption("folds", std::to_string(folds), "an integer in [2, 64]");
  if (!(ramp_rate_k_per_min > 0.0 && ramp_rate_k_per_min <= 100.0)) {
    ThrowOption("ramp_rate_k_per_min", FormatValue(ramp_rate_k_per_min), "in (0, 100]");
  }
  if (hysteresis_widths_k.size() > kMostHysteresisWidths) {
    ThrowOption("hysteresis_widths_k", std::to_string(hysteresis_widths_k.size()) + " widths",
                "at most " + std::to_string(kMostHysteresisWidths));
  }
  for (double w : hysteresis_widths_k) RequireInRange("hysteresis_widths_k", w, 1e-9, 100.0);
  if (hysteresis == HysteresisTerm::kOn && hysteresis_widths_k.empty()) {
    ThrowOption("hysteresis_widths_k", "none", "at least one width with hysteresis 'on'");
  }
  RequireInRange("max_condition", max_condition, 1e2, 1e16);
  RequireInRange("standard_errors", standard_errors, 0.0, 10.0);
}

bool ThermalModelOptions::TriesHysteresis(double logged_s) const {
  if (hysteresis_widths_k.empty()) return false;
  switch (hysteresis) {
    case HysteresisTerm::kOn:
      return true;
    case HysteresisTerm::kOff:
      return false;
    case HysteresisTerm::kAuto:
      break;
  }
  return logged_s >= kHysteresisAutoMinDurationS;
}

std::string_view ToString(HysteresisTerm term) {
  return gyrodrift::internal::EnumName(term, kHysteresisTerms);
}

HysteresisTerm HysteresisTermFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "hysteresis", kHysteresisTerms);
}

std::vector<double> ThermalModelOptions::Grid(double duration_s) const {
  const double longest = std::min(longest_tau_s, longest_tau_share * duration_s);
  std::vector<double> grid;
  for (int k = 0;; ++k) {
    const double tau = shortest_tau_s * std::exp2(static_cast<double>(k) / taus_per_octave);
    if (tau > longest * (1.0 + 1e-12)) break;
    grid.push_back(tau);
  }
  return grid;
}

double ThermalModelOptions::HoursReachingLag(double lag_s) const {
  const double steps =
      std::ceil(taus_per_octave * std::log2(lag_s / state_order / shortest_tau_s) - 1e-9);
  const double run_s =
      shortest_tau_s * std::exp2(std::max(steps, 0.0) / taus_per_octave) / longest_tau_share;
  return std::ceil(run_s / 36.0) / 100.0;
}

Eigen::MatrixXd ThermalRegression::Regressors(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  return Regressors(temperatures_c, record_starts, /*within_support=*/true);
}

Eigen::MatrixXd ThermalRegression::Regressors(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts, bool within_support) const {
  if (temperatures_c.cols() != channels()) {
    throw DataError("the thermal model takes " + std::to_string(channels()) +
                    " temperature channel(s), " + std::to_string(temperatures_c.cols()) +
                    " given");
  }
  const Eigen::Index n = temperatures_c.rows();
  for (int c = 0; c < channels(); ++c) {
    RequireFiniteSignal("temperature", temperatures_c.col(c), 1);
  }
  CheckRecordStarts(record_starts, n);
  Eigen::MatrixXd x(n, coefficients.size());
  Eigen::Index col = 0;
  x.col(col++).setOnes();
  for (int c = 0; c < channels(); ++c) {
    const auto cu = static_cast<size_t>(c);
    if (static_power[cu] == 0) continue;
    const Eigen::VectorXd z = (temperatures_c.col(c).array() - centre_c[cu]) / scale_k[cu];
    StaticColumns(z, static_power[cu], static_min[cu], static_max[cu],
                  x.middleCols(col, static_power[cu]));
    col += static_power[cu];
  }
  Eigen::VectorXd level, hysteresis_level;
  for (size_t j = 0; j < states.size(); ++j) {
    ThermalState s = states[j];
    const auto c = static_cast<size_t>(s.channel);
    StateColumns(temperatures_c.col(s.channel), s, order, max_power, 1.0 / rate_hz, centre_c[c],
                 scale_k[c], /*learn_range=*/false, within_support, record_starts, {},
                 x.middleCols(col, max_power + 1), level);
    if (static_cast<int>(j) == hysteresis_state) hysteresis_level.swap(level);
    col += max_power + 1;
  }
  if (has_hysteresis()) {
    HysteresisColumns(hysteresis_level, {hysteresis_width_k}, record_starts, x.middleCols(col, 1));
  }
  return x;
}

std::vector<std::string> ThermalRegression::RegressorNames(
    const std::vector<std::string>& channel_names) const {
  using gyrodrift::internal::Format;
  auto channel = [&](int c) {
    return static_cast<int>(channel_names.size()) == channels()
               ? channel_names[static_cast<size_t>(c)]
               : Format("T%d", c + 1);
  };
  std::vector<std::string> names{"1"};
  for (int c = 0; c < channels(); ++c) {
    for (int p = 1; p <= static_power[static_cast<size_t>(c)]; ++p) {
      names.push_back(p == 1 ? channel(c) : Format("%s^%d", channel(c).c_str(), p));
    }
  }
  for (const ThermalState& s : states) {
    const std::string state =
        Format("L%d(%s; %.4g s)", order, channel(s.channel).c_str(), s.tau_s);
    names.push_back(state);
    for (int p = 2; p <= max_power; ++p) names.push_back(Format("%s^%d", state.c_str(), p));
    names.push_back("d/dt " + state);
  }
  if (has_hysteresis()) {
    const ThermalState& s = states[static_cast<size_t>(hysteresis_state)];
    names.push_back(Format("H(L%d(%s; %.4g s); %g K)", order, channel(s.channel).c_str(), s.tau_s,
                           hysteresis_width_k));
  }
  return names;
}

Eigen::VectorXd ThermalRegression::Estimate(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  const Eigen::MatrixXd x = Regressors(temperatures_c, record_starts);
  return EstimateOf(x);
}

Eigen::VectorXd ThermalRegression::EstimateOf(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  Eigen::VectorXd estimate = x * coefficients;
  if (correction) estimate += correction->Predict(x.rightCols(x.cols() - 1));
  return estimate;
}

Eigen::MatrixXd ThermalRegression::EstimateWithSd(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  const Eigen::MatrixXd x = Regressors(temperatures_c, record_starts);
  Eigen::MatrixXd out(x.rows(), 2);
  out.col(0) = EstimateOf(x);
  const Eigen::MatrixXd xv = x * covariance;
  Eigen::ArrayXd variance =
      (xv.cwiseProduct(x)).rowwise().sum().array().max(0.0) + cv_slow_sd * cv_slow_sd;
  if (!states.empty()) {
    // What the rates' share beyond their range left out (the run cannot tell the share).
    const Eigen::VectorXd unheld =
        (Regressors(temperatures_c, record_starts, /*within_support=*/false) - x) * coefficients;
    variance += unheld.array().square();
  }
  out.col(1) = variance.sqrt().matrix();
  return out;
}

std::string ThermalRegression::Summary() const {
  using gyrodrift::internal::Format;
  std::string chosen;
  for (const ThermalState& s : states) {
    chosen += Format("%s%.4g s", chosen.empty() ? "" : ", ", s.tau_s);
    if (channels() > 1) chosen += Format(" (T%d)", s.channel + 1);
  }
  const int powers = *std::max_element(static_power.begin(), static_power.end());
  const std::string in_t = powers == 0   ? std::string()
                           : powers == 1 ? std::string(", linear in T")
                                         : Format(", powers of T to %d", powers);
  const std::string hysteresis =
      has_hysteresis()
          ? Format(", hysteresis of the %.4g-s state (play %g K)",
                   states[static_cast<size_t>(hysteresis_state)].tau_s, hysteresis_width_k)
          : std::string();
  return Format("thermal states [%s] of order %d to power %d%s%s, cross-validated RMSE %.4g",
                chosen.empty() ? "none" : chosen.c_str(), order, max_power, in_t.c_str(),
                hysteresis.c_str(), report.cv_rmse);
}

double AutopilotForm::Estimate(double temperature_c) const {
  const double dt = std::clamp(temperature_c, tmin_c, tmax_c) - tref_c;
  return coefficients[0] + dt * (coefficients[1] + dt * (coefficients[2] + dt * coefficients[3]));
}

std::string AutopilotForm::Summary() const {
  using gyrodrift::internal::Format;
  static constexpr std::array<const char*, 4> kDegree{"constant", "linear", "quadratic", "cubic"};
  const std::string kept =
      std::isnan(share_kept)
          ? std::string("its share of what the full model removes not measured")
          : Format("keeps %.1f %% of the slow drift the full model removes (held out)",
                   100.0 * share_kept);
  return Format("%s in (T - %.4g degC), T held within [%.4g, %.4g] degC: %s",
                kDegree[static_cast<size_t>(std::clamp(degree, 0, 3))], tref_c, tmin_c, tmax_c,
                kept.c_str());
}

void ThermalRegression::Validate() const {
  const size_t c = centre_c.size();
  if (c == 0 || scale_k.size() != c || static_power.size() != c || static_min.size() != c ||
      static_max.size() != c) {
    throw DataError("thermal model: channel fields of unequal length (or none)");
  }
  for (size_t i = 0; i < c; ++i) {
    if (!std::isfinite(centre_c[i]) || !(scale_k[i] > 0.0) || !std::isfinite(scale_k[i])) {
      throw DataError("thermal model: channel " + std::to_string(i + 1) +
                      " needs a finite centre and a positive scale");
    }
    if (static_power[i] < 0 || static_power[i] > 3 || !(static_min[i] <= static_max[i]) ||
        (static_power[i] > 1 && !(std::isfinite(static_min[i]) && std::isfinite(static_max[i])))) {
      throw DataError("thermal model: channel " + std::to_string(i + 1) +
                      " needs a static power in [0, 3] and a finite range for powers above 1");
    }
  }
  if (!(rate_hz > 0.0) || order < 1 || order > 4 || max_power < 1 || max_power > 3) {
    throw DataError("thermal model: rate_hz, order or max_power out of range");
  }
  for (const ThermalState& s : states) {
    if (s.channel < 0 || s.channel >= channels() || !(s.tau_s >= 1e-9) || !std::isfinite(s.tau_s) ||
        !(s.level_min <= s.level_max) || !std::isfinite(s.level_min) ||
        !std::isfinite(s.level_max) || !(s.rate_min <= s.rate_max) || std::isnan(s.rate_min) ||
        std::isnan(s.rate_max) || !(s.rate_beyond >= 0.0 && s.rate_beyond <= 1.0)) {
      throw DataError(
          "thermal model: a state's channel, time constant, level or rate range is out of "
          "range, or its rate_beyond is outside [0, 1]");
    }
  }
  if (hysteresis_state < -1 || hysteresis_state >= static_cast<int>(states.size()) ||
      (has_hysteresis() && !(hysteresis_width_k > 0.0 && std::isfinite(hysteresis_width_k)))) {
    throw DataError("thermal model: the hysteresis term names no state or a width out of range");
  }
  const Eigen::Index m = static_cast<Eigen::Index>(
      1 + std::accumulate(static_power.begin(), static_power.end(), 0) +
      static_cast<long>(states.size()) * (max_power + 1) + (has_hysteresis() ? 1 : 0));
  if (correction && correction->num_inputs() != m - 1) {
    throw DataError("thermal model: the nonlinear correction takes " +
                    std::to_string(correction->num_inputs()) + " inputs, not the " +
                    std::to_string(m - 1) + " regressors");
  }
  if (coefficients.size() != m || covariance.rows() != m || covariance.cols() != m ||
      !coefficients.allFinite() || !covariance.allFinite() || !(cv_slow_sd >= 0.0)) {
    throw DataError("thermal model: " + std::to_string(coefficients.size()) +
                    " coefficients (and covariance) for " + std::to_string(m) +
                    " regressors, or non-finite values");
  }
  if (autopilot.fitted()) {
    const AutopilotForm& a = autopilot;
    bool finite = std::isfinite(a.tref_c) && a.degree <= 3;
    for (size_t k = 0; k < a.coefficients.size(); ++k) {
      finite = finite && std::isfinite(a.coefficients[k]) &&
               (static_cast<int>(k) <= a.degree || a.coefficients[k] == 0.0);
    }
    if (!finite || !(a.tmin_c <= a.tref_c && a.tref_c <= a.tmax_c)) {
      throw DataError("thermal model: the autopilot form needs a degree in [0, 3], finite "
                      "coefficients (0 above the degree) and tmin_c <= tref_c <= tmax_c");
    }
  }
}

}  // namespace gyrodrift::drift
