// Model inputs built from a gyro log: own lags of a series, and the thermal history of the
// temperature channel.
//
// Thermal history [choice, measured in docs/drift.md]: the coil's temperature lags the case
// sensor by minutes to an hour, the Shupe drift follows temperature *rates* inside the coil, the
// stress drift the coil's mean temperature and the static bias the case temperature
// (METHOD.md section 1). A bank of first-order lags of the measured temperature T, one per time
// constant tau, stands in for the temperature at different depths of the winding pack:
//   T_tau[t] = T_tau[t-1] + (1 - exp(-dt/tau)) (T[t] - T_tau[t-1]),   T_tau[0] = T[0].
// Feature sets (ThermalSet):
//   kLadder   (default for every method but poly) the band-pass ladder T - T_tau1,
//             T_tau1 - T_tau2, ..., T_tau(K-1) - T_tauK (K columns in K, each a smoothed rate
//             times its time scale); the slowest lag T_tauK; and (T - 20 degC)^2 (static-bias
//             curvature). K + 2 columns (T and (T - 20)^2 when K = 0). Rungs plus the slowest lag
//             add up to T, so the ladder spans the same space as {T, T_tau} (and every lag rate
//             (T - T_tau)/tau), but its columns are far less correlated, which a sigmoid network
//             needs (the raw lags of one temperature are correlated above 0.99).
//   kClassic  (poly's default) the classic thermal-drift regression inputs: T and the smoothed
//             rate (T - T_tau1) / tau1 in K/s (tau1 = first time constant, 60 s by default).
//   kLagBank  the original bank: T, then per tau T_tau and (T - T_tau) / tau (1 + 2K columns).
// Every feature at t uses T[0..t] only (causal), and the recursion is what a navigation computer
// would run. Cost: O(N * number of time constants).
#pragma once

#include <Eigen/Core>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/records.h"

namespace gyrodrift::drift {

enum class ThermalSet { kAuto, kLadder, kClassic, kLagBank };
std::string_view ToString(ThermalSet set);
ThermalSet ThermalSetFromString(std::string_view name);  // "auto", "ladder", "classic", "lag-bank"

struct FeatureOptions {
  // Own lags p of each series in predict mode, in [1, 256].
  int lags = 4;
  // Predict mode: also give each sub-model the thermal history (needs a temperature channel).
  bool use_temperature = false;
  // Time constants of the thermal-history bank, seconds, each in [1, 1e6]; may be empty (then
  // only T itself is a feature).
  std::vector<double> time_constants_s{60.0, 300.0, 900.0, 1800.0, 3600.0};
  // At fit time, drop the time constants longer than a quarter of the training record (the
  // shortest is always kept): a lag as slow as the record is indistinguishable from a trend and
  // makes the thermal fit extrapolate wildly (docs/drift.md section 1.1). The fitted model stores
  // the constants it kept, with this off. `fit --time-constants` turns it off.
  bool limit_time_constants = true;
  double rate_hz = 1.0;  // sample rate of the log, Hz, in (0, 1e6]
  // Which thermal features; kAuto = kClassic for the poly method, kLadder otherwise (the drift
  // model resolves it; ThermalFeatures itself treats kAuto as kLadder). kClassic needs at least
  // one time constant.
  ThermalSet thermal_set = ThermalSet::kAuto;
  void Validate() const;  // throws UsageError naming the field
  bool operator==(const FeatureOptions&) const = default;
  // Columns of ThermalFeatures for thermal_set (kAuto counted as kLadder).
  int NumThermalFeatures() const;
};

// N x NumThermalFeatures() matrix of the thermal history of temperature_c (degC). Throws
// DataError on a non-finite sample or an empty record.
Eigen::MatrixXd ThermalFeatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                const FeatureOptions& options);

// The options with limit_time_constants applied for a training record of `samples` samples at
// options.rate_hz (and the flag cleared).
FeatureOptions ForTrainingRecord(FeatureOptions options, Eigen::Index samples);

// The first-order lag of temperature_c with time constant tau_s at sample spacing dt_s, into out
// (N): out[t] = out[t-1] + (1 - exp(-dt/tau)) (T[t] - out[t-1]), started in equilibrium at T[0]
// (the exact one-sample step response; stable for any dt / tau).
void FirstOrderLag(const Eigen::Ref<const Eigen::VectorXd>& temperature_c, double tau_s,
                   double dt_s, Eigen::Ref<Eigen::VectorXd> out);
// Its gain 1 - exp(-dt/tau), the one formula every lag uses (firmware export prints it as a
// literal so that generated C code runs the same recursion).
double FirstOrderLagGain(double tau_s, double dt_s);

// Rows of lags: row r holds s[t-1], ..., s[t-p] for t = first + r, r = 0..count-1 (first >= p).
Eigen::MatrixXd LagRows(const Eigen::Ref<const Eigen::VectorXd>& s, int p, Eigen::Index first,
                        Eigen::Index count);

}  // namespace gyrodrift::drift
