#include "gyrodrift/drift/thermal_coefficients.h"

#include <algorithm>
#include <cmath>

#include "gyrodrift/common/check.h"

namespace gyrodrift::drift {
namespace {

double Binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

// The k-th Taylor coefficient at z0 of a state's p-th power column as ThermalRegression builds
// it: z^p inside [lo, hi], continued along its tangent beyond (p >= 2); z itself for p = 1.
double TaylorOfPower(int p, int k, double z0, double lo, double hi) {
  if (p == 1) return k == 0 ? z0 : k == 1 ? 1.0 : 0.0;
  const double edge = std::clamp(z0, lo, hi);
  if (edge == z0) return k > p ? 0.0 : Binomial(p, k) * std::pow(z0, p - k);
  switch (k) {
    case 0:
      return std::pow(edge, p) + p * std::pow(edge, p - 1) * (z0 - edge);
    case 1:
      return p * std::pow(edge, p - 1);
    default:
      return 0.0;
  }
}

}  // namespace

ThermalCoefficients PhysicalCoefficients(const ThermalRegression& model,
                                         std::optional<double> reference_c,
                                         const std::vector<std::string>& channel_names) {
  model.Validate();
  if (reference_c && !std::isfinite(*reference_c)) {
    ThrowOption("reference_c", FormatValue(*reference_c), "a finite temperature, degC");
  }
  ThermalCoefficients out;
  const int channels = model.channels();
  std::vector<double> z0(static_cast<size_t>(channels));
  for (int c = 0; c < channels; ++c) {
    const auto i = static_cast<size_t>(c);
    out.reference_c.push_back(reference_c.value_or(model.centre_c[i]));
    z0[i] = (out.reference_c[i] - model.centre_c[i]) / model.scale_k[i];
  }
  const Eigen::Index m = model.coefficients.size();
  Eigen::MatrixXd& a = out.transform;
  a = Eigen::MatrixXd::Zero(m, m);
  const std::vector<std::string> names = model.RegressorNames(channel_names);
  out.terms.resize(static_cast<size_t>(m));
  auto term = [&](Eigen::Index row, int power, const char* unit, int state = -1) {
    PhysicalCoefficient& t = out.terms[static_cast<size_t>(row)];
    t.term = names[static_cast<size_t>(row)];
    t.power = power;
    t.unit = unit;
    t.state = state;
  };
  // Row 0: the bias at the reference, every column's value in equilibrium there.
  a(0, 0) = 1.0;
  term(0, 0, "");
  out.terms[0].term = "bias";
  static constexpr const char* kPowerUnits[] = {"", "/K", "/K^2", "/K^3"};
  Eigen::Index col = 1;
  // A block of powers 1..powers of a standardised level (a channel's, or a state's) about z0:
  // the bias row takes their values at z0, the row of u^k their k-th Taylor coefficients per K^k.
  auto powers_block = [&](int powers, double z0_level, double scale, double lo, double hi,
                          int state) {
    for (int p = 1; p <= powers; ++p) a(0, col + p - 1) = TaylorOfPower(p, 0, z0_level, lo, hi);
    for (int k = 1; k <= powers; ++k) {
      for (int p = k; p <= powers; ++p) {
        a(col + k - 1, col + p - 1) = TaylorOfPower(p, k, z0_level, lo, hi) / std::pow(scale, k);
      }
      term(col + k - 1, k, kPowerUnits[k], state);
    }
    col += powers;
  };
  for (int c = 0; c < channels; ++c) {
    const auto i = static_cast<size_t>(c);
    powers_block(model.static_power[i], z0[i], model.scale_k[i], model.static_min[i],
                 model.static_max[i], -1);
  }
  const int powers = model.max_power;
  for (size_t j = 0; j < model.states.size(); ++j) {
    const ThermalState& s = model.states[j];
    const int state = static_cast<int>(j);
    const auto i = static_cast<size_t>(s.channel);
    const double scale = model.scale_k[i];
    out.state_range_c.emplace_back(model.centre_c[i] + scale * s.level_min,
                                   model.centre_c[i] + scale * s.level_max);
    powers_block(powers, z0[i], scale, s.level_min, s.level_max, state);
    a(col, col) = 1.0 / 60.0;  // K/s to K/min
    term(col, 1, "/(K/min)", state);
    ++col;
  }
  if (model.has_hysteresis()) {
    a(col, col) = 1.0;
    term(col, 0, "", model.hysteresis_state);
  }
  const Eigen::VectorXd value = a * model.coefficients;
  const Eigen::MatrixXd covariance = a * model.covariance * a.transpose();
  for (Eigen::Index r = 0; r < m; ++r) {
    out.terms[static_cast<size_t>(r)].value = value[r];
    out.terms[static_cast<size_t>(r)].sd = std::sqrt(std::max(0.0, covariance(r, r)));
  }
  return out;
}

}  // namespace gyrodrift::drift
