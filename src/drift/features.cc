#include "gyrodrift/drift/features.h"

#include <cmath>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {

void FeatureOptions::Validate() const {
  if (lags < 1 || lags > 256) ThrowOption("lags", std::to_string(lags), "an integer in [1, 256]");
  for (double tau : time_constants_s) RequireInRange("time constant (s)", tau, 1.0, 1e6);
  if (time_constants_s.size() > 32) {
    ThrowOption("time constants", std::to_string(time_constants_s.size()), "at most 32 values");
  }
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
}

Eigen::MatrixXd ThermalFeatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                const FeatureOptions& options) {
  options.Validate();
  RequireFiniteSignal("temperature", temperature_c, 1);
  const Eigen::Index n = temperature_c.size();
  const int taus = static_cast<int>(options.time_constants_s.size());
  Eigen::MatrixXd f(n, options.NumThermalFeatures());
  f.col(0) = temperature_c;
  const double dt = 1.0 / options.rate_hz;
  for (int k = 0; k < taus; ++k) {
    const double tau = options.time_constants_s[static_cast<size_t>(k)];
    // Exact step response of a first-order lag over one sample (stable for any dt / tau).
    const double gain = -std::expm1(-dt / tau);
    double state = temperature_c[0];
    for (Eigen::Index t = 0; t < n; ++t) {
      state += gain * (temperature_c[t] - state);
      f(t, 1 + 2 * k) = state;
      f(t, 2 + 2 * k) = (temperature_c[t] - state) / tau;
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
