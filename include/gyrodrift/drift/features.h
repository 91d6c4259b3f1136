// Model inputs built from a gyro log: own lags of a series, and the thermal history of the
// temperature channel.
//
// Thermal history [choice, documented in docs/drift.md]: the coil's temperature lags the case
// sensor by minutes to an hour, and the Shupe drift follows temperature *rates* inside the coil
// (METHOD.md section 1). A bank of first-order lags of the measured temperature, one per time
// constant tau, stands in for the temperature at different depths of the winding pack:
//   T_tau[t] = T_tau[t-1] + (1 - exp(-dt/tau)) (T[t] - T_tau[t-1]),   T_tau[0] = T[0],
// and (T - T_tau) / tau is the rate of T_tau (K/s), a smoothed rate at that depth. Features at
// sample t: T[t], then for each tau: T_tau[t] and (T[t] - T_tau[t]) / tau. Every feature at t
// uses T[0..t] only (causal), and the recursion is what a navigation computer would run.
// Cost: O(N * number of time constants).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace gyrodrift::drift {

struct FeatureOptions {
  // Own lags p of each series in predict mode, in [1, 256].
  int lags = 4;
  // Predict mode: also give each sub-model the thermal history (needs a temperature channel).
  bool use_temperature = false;
  // Time constants of the thermal-history bank, seconds, each in [1, 1e6]; may be empty (then
  // only T itself is a feature).
  std::vector<double> time_constants_s{60.0, 300.0, 900.0, 1800.0, 3600.0};
  double rate_hz = 1.0;  // sample rate of the log, Hz, in (0, 1e6]
  void Validate() const;  // throws UsageError naming the field
  int NumThermalFeatures() const { return 1 + 2 * static_cast<int>(time_constants_s.size()); }
};

// N x NumThermalFeatures() matrix of the thermal history of temperature_c (degC). Throws
// DataError on a non-finite sample or an empty record.
Eigen::MatrixXd ThermalFeatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                const FeatureOptions& options);

// Rows of lags: row r holds s[t-1], ..., s[t-p] for t = first + r, r = 0..count-1 (first >= p).
Eigen::MatrixXd LagRows(const Eigen::Ref<const Eigen::VectorXd>& s, int p, Eigen::Index first,
                        Eigen::Index count);

}  // namespace gyrodrift::drift
