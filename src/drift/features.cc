#include "gyrodrift/drift/features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {

namespace {

constexpr std::array<std::pair<ThermalSet, std::string_view>, 4> kSets{{
    {ThermalSet::kAuto, "auto"},
    {ThermalSet::kLadder, "ladder"},
    {ThermalSet::kClassic, "classic"},
    {ThermalSet::kLagBank, "lag-bank"},
}};

// Centre of the quadratic column: keeps (T - c)^2 well scaled for chamber temperatures; any
// centre spans the same space together with T and the constant.
constexpr double kQuadraticCentreC = 20.0;

}  // namespace

double FirstOrderLagGain(double tau_s, double dt_s) { return -std::expm1(-dt_s / tau_s); }

void FirstOrderLag(const Eigen::Ref<const Eigen::VectorXd>& temperature_c, double tau_s,
                   double dt_s, Eigen::Ref<Eigen::VectorXd> out) {
  const double gain = FirstOrderLagGain(tau_s, dt_s);
  double state = temperature_c[0];
  for (Eigen::Index t = 0; t < temperature_c.size(); ++t) {
    state += gain * (temperature_c[t] - state);
    out[t] = state;
  }
}

std::string_view ToString(ThermalSet set) { return gyrodrift::internal::EnumName(set, kSets); }

ThermalSet ThermalSetFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "thermal_set", kSets);
}

int FeatureOptions::NumThermalFeatures() const {
  const int taus = static_cast<int>(time_constants_s.size());
  switch (thermal_set) {
    case ThermalSet::kClassic:
      return 2;
    case ThermalSet::kLagBank:
      return 1 + 2 * taus;
    default:
      return 2 + taus;
  }
}

void FeatureOptions::Validate() const {
  if (lags < 1 || lags > 256) ThrowOption("lags", std::to_string(lags), "an integer in [1, 256]");
  for (size_t i = 0; i < time_constants_s.size(); ++i) {
    RequireInRange("time_constants_s", time_constants_s[i], 1.0, 1e6);
    // A repeat would add the same lag twice: two identical columns.
    for (size_t j = 0; j < i; ++j) {
      if (time_constants_s[j] == time_constants_s[i]) {
        ThrowOption("time_constants_s", FormatValue(time_constants_s[i]),
                    "given once (a list without repeats)");
      }
    }
  }
  if (time_constants_s.size() > 32) {
    ThrowOption("time_constants_s", std::to_string(time_constants_s.size()) + " values",
                "at most 32");
  }
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
  if (thermal_set == ThermalSet::kClassic && time_constants_s.empty()) {
    ThrowOption("time_constants_s", "(empty)",
                "at least one value with thermal_set = classic (the first smooths the rate)");
  }
}

FeatureOptions ForTrainingRecord(FeatureOptions options, Eigen::Index samples) {
  if (options.limit_time_constants && !options.time_constants_s.empty()) {
    // A rate read from time_s carries rounding (10 Hz can be 10.000000000003 Hz): a constant
    // exactly at the limit must not depend on it.
    const double limit_s = 0.25 * static_cast<double>(samples) / options.rate_hz * (1.0 + 1e-9);
    const double shortest =
        *std::min_element(options.time_constants_s.begin(), options.time_constants_s.end());
    std::vector<double> kept;
    for (double tau : options.time_constants_s) {
      if (tau <= limit_s || tau == shortest) kept.push_back(tau);
    }
    options.time_constants_s = std::move(kept);
  }
  options.limit_time_constants = false;
  return options;
}

Eigen::MatrixXd ThermalFeatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                const FeatureOptions& options) {
  options.Validate();
  RequireFiniteSignal("temperature", temperature_c, 1);
  const Eigen::Index n = temperature_c.size();
  const int taus = static_cast<int>(options.time_constants_s.size());
  const double dt = 1.0 / options.rate_hz;
  Eigen::MatrixXd f(n, options.NumThermalFeatures());
  Eigen::VectorXd lag(n);
  switch (options.thermal_set) {
    case ThermalSet::kClassic: {
      const double tau = options.time_constants_s.front();
      FirstOrderLag(temperature_c, tau, dt, lag);
      f.col(0) = temperature_c;
      f.col(1) = (temperature_c - lag) / tau;
      break;
    }
    case ThermalSet::kLagBank:
      f.col(0) = temperature_c;
      for (int k = 0; k < taus; ++k) {
        const double tau = options.time_constants_s[static_cast<size_t>(k)];
        FirstOrderLag(temperature_c, tau, dt, lag);
        f.col(1 + 2 * k) = lag;
        f.col(2 + 2 * k) = (temperature_c - lag) / tau;
      }
      break;
    default: {
      // Ladder rung k: the band of thermal history between two neighbouring depths (K). The rungs
      // and the slowest lag add up to T, so T itself would be a redundant column.
      Eigen::VectorXd previous = temperature_c;
      for (int k = 0; k < taus; ++k) {
        FirstOrderLag(temperature_c, options.time_constants_s[static_cast<size_t>(k)], dt, lag);
        f.col(k) = previous - lag;
        previous = lag;
      }
      f.col(taus) = previous;
      f.col(f.cols() - 1) = (temperature_c.array() - kQuadraticCentreC).square().matrix();
      break;
    }
  }
  return f;
}

Eigen::MatrixXd LagRows(const Eigen::Ref<const Eigen::VectorXd>& s, int p, Eigen::Index first,
                        Eigen::Index count) {
  Eigen::MatrixXd rows(count, p);
  for (Eigen::Index r = 0; r < count; ++r) {
    const Eigen::Index t = first + r;
    for (int k = 0; k < p; ++k) rows(r, k) = s[t - 1 - k];
  }
  return rows;
}

}  // namespace gyrodrift::drift
