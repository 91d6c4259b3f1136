#include "gyrodrift/simulation/coil_thermal.h"

#include <cmath>
#include <string>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

constexpr gyrodrift::internal::EnumNames<ThermalScheme, 2> kSchemes{{
    {ThermalScheme::kBackwardEuler, "backward-euler"},
    {ThermalScheme::kCrankNicolson, "crank-nicolson"},
}};

}  // namespace

std::string_view ToString(ThermalScheme scheme) {
  return gyrodrift::internal::EnumName(scheme, kSchemes);
}

ThermalScheme ThermalSchemeFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "thermal.scheme", kSchemes);
}

void ThermalParameters::Validate() const {
  RequireInRange("thermal.diffusivity_m2_s", diffusivity_m2_s, 1e-8, 1e-5);
  RequireInRange("thermal.conductivity_w_mk", conductivity_w_mk, 0.01, 50.0);
  RequireInRange("thermal.outer_conductance_w_m2k", outer_conductance_w_m2k, 0.01, 1e9);
  RequireInRange("thermal.inner_conductance_w_m2k", inner_conductance_w_m2k, 0.01, 1e9);
  RequireInRange("thermal.case_time_constant_s", case_time_constant_s, 1.0, 1e6);
  RequireInRange("thermal.max_step_s", max_step_s, 1e-4, 3600.0);
}

double LagStep(double x, double u_old, double u_new, double step_s, double tau_s) {
  // x(t) = u(t) - s tau + (x0 - u0 + s tau) exp(-t / tau) for u(t) = u0 + s t.
  const double slope_tau = (u_new - u_old) / step_s * tau_s;
  const double decay = std::exp(-step_s / tau_s);
  return u_new - slope_tau + (x - u_old + slope_tau) * decay;
}

RadialConduction::RadialConduction(double inner_radius_m, double outer_radius_m, int cells,
                                   const ThermalParameters& params) {
  params.Validate();
  RequirePositive("coil inner radius (m)", inner_radius_m);
  if (!(outer_radius_m > inner_radius_m) || !std::isfinite(outer_radius_m)) {
    ThrowOption("outer_radius_m", FormatValue(outer_radius_m),
                "finite and > the inner radius " + FormatValue(inner_radius_m));
  }
  if (cells < 1 || cells > 100000) ThrowOption("cells", std::to_string(cells), "in [1, 100000]");
  theta_ = params.scheme == ThermalScheme::kBackwardEuler ? 1.0 : 0.5;
  const double a = params.diffusivity_m2_s, k = params.conductivity_w_mk;
  const double dr = (outer_radius_m - inner_radius_m) / cells;
  radius_.resize(cells);
  volume_.resize(cells);
  face_g_ = Eigen::VectorXd::Zero(cells);
  for (int i = 0; i < cells; ++i) {
    radius_[i] = inner_radius_m + (i + 0.5) * dr;
    volume_[i] = radius_[i] * dr;
    if (i > 0) face_g_[i] = a * (inner_radius_m + i * dr) / dr;
  }
  // Film resistance in series with the half ring between the face and the first ring centre.
  g_in_ = a / k * inner_radius_m / (1.0 / params.inner_conductance_w_m2k + 0.5 * dr / k);
  g_out_ = a / k * outer_radius_m / (1.0 / params.outer_conductance_w_m2k + 0.5 * dr / k);
  diag_g_.resize(cells);
  for (int i = 0; i < cells; ++i) {
    diag_g_[i] = (i > 0 ? face_g_[i] : g_in_) + (i + 1 < cells ? face_g_[i + 1] : 0.0);
  }
  diag_g_[cells - 1] += g_out_;
  t_ = Eigen::VectorXd::Zero(cells);
  rhs_.resize(cells);
  lower_.resize(cells);
  upper_prime_.resize(cells);
  inverse_pivot_.resize(cells);
  volume_per_step_.resize(cells);
  inverse_total_volume_ = 1.0 / volume_.sum();
}

void RadialConduction::SetUniform(double temperature_c) { t_.setConstant(temperature_c); }

void RadialConduction::SetTemperatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c) {
  if (temperature_c.size() != t_.size()) {
    throw UsageError("temperatures: " + std::to_string(temperature_c.size()) + " values for " +
                     std::to_string(t_.size()) + " rings");
  }
  t_ = temperature_c;
}

void RadialConduction::Factorise(double step_s) {
  const int n = cells();
  // Step matrix: volume / step + theta * G; G has diag_g_ on the diagonal, -face_g_ off it.
  for (int i = 0; i < n; ++i) {
    const double diag = volume_[i] / step_s + theta_ * diag_g_[i];
    const double lower = i > 0 ? -theta_ * face_g_[i] : 0.0;
    const double upper = i + 1 < n ? -theta_ * face_g_[i + 1] : 0.0;
    lower_[i] = lower;
    const double pivot = diag - (i > 0 ? lower * upper_prime_[i - 1] : 0.0);
    inverse_pivot_[i] = 1.0 / pivot;
    upper_prime_[i] = upper / pivot;
    volume_per_step_[i] = volume_[i] / step_s;
  }
  factor_step_s_ = step_s;
}

void RadialConduction::Step(double step_s, double inner_old_c, double inner_new_c,
                            double outer_old_c, double outer_new_c) {
  if (step_s != factor_step_s_) Factorise(step_s);
  const int n = cells();
  const double explicit_share = 1.0 - theta_;
  double* t = t_.data();
  double* r = rhs_.data();
  const double* vh = volume_per_step_.data();
  if (explicit_share > 0.0) {
    const double* g = face_g_.data();
    const double* d = diag_g_.data();
    for (int i = 0; i < n; ++i) {
      double flow = -d[i] * t[i];
      if (i > 0) flow += g[i] * t[i - 1];
      if (i + 1 < n) flow += g[i + 1] * t[i + 1];
      r[i] = vh[i] * t[i] + explicit_share * flow;
    }
  } else {
    for (int i = 0; i < n; ++i) r[i] = vh[i] * t[i];
  }
  r[0] += g_in_ * (theta_ * inner_new_c + explicit_share * inner_old_c);
  r[n - 1] += g_out_ * (theta_ * outer_new_c + explicit_share * outer_old_c);
  // Thomas: forward sweep with the cached pivots, then back substitution into t_.
  const double* lower = lower_.data();
  const double* inverse_pivot = inverse_pivot_.data();
  const double* upper_prime = upper_prime_.data();
  r[0] *= inverse_pivot[0];
  for (int i = 1; i < n; ++i) r[i] = (r[i] - lower[i] * r[i - 1]) * inverse_pivot[i];
  t[n - 1] = r[n - 1];
  for (int i = n - 2; i >= 0; --i) t[i] = r[i] - upper_prime[i] * t[i + 1];
}

double RadialConduction::MeanTemperature() const { return volume_.dot(t_) * inverse_total_volume_; }

Eigen::VectorXd RadialConduction::SolveSteady(const Eigen::VectorXd& rhs) const {
  const int n = cells();
  Eigen::VectorXd c(n), d(n), x(n);
  for (int i = 0; i < n; ++i) {
    const double lower = i > 0 ? -face_g_[i] : 0.0;
    const double upper = i + 1 < n ? -face_g_[i + 1] : 0.0;
    const double pivot = diag_g_[i] - (i > 0 ? lower * c[i - 1] : 0.0);
    c[i] = upper / pivot;
    d[i] = (rhs[i] - (i > 0 ? lower * d[i - 1] : 0.0)) / pivot;
  }
  x[n - 1] = d[n - 1];
  for (int i = n - 2; i >= 0; --i) x[i] = d[i] - c[i] * x[i + 1];
  return x;
}

Eigen::VectorXd RadialConduction::SteadyState(double inner_c, double outer_c) const {
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(cells());
  rhs[0] += g_in_ * inner_c;
  rhs[cells() - 1] += g_out_ * outer_c;
  return SolveSteady(rhs);
}

double RadialConduction::RampLagSeconds() const {
  // With both boundaries at s t, ring i settles to s (t - phi_i) where G phi = volume.
  const Eigen::VectorXd phi = SolveSteady(volume_);
  return volume_.dot(phi) / volume_.sum();
}

}  // namespace gyrodrift::simulation
