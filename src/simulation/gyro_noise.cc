#include "gyrodrift/simulation/gyro_noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/simulation/coil_thermal.h"

namespace gyrodrift::simulation {
namespace {

// Unit conversions of the IEEE 952 terms to deg/h and seconds.
constexpr double kArwToDphRootS = 60.0;           // 1 deg/sqrt(h) = 60 deg/h * sqrt(s)
constexpr double kRrwToDphPerRootS = 1.0 / 60.0;  // 1 deg/h/sqrt(h) = 1/60 deg/h/sqrt(s)
constexpr double kRampToDphPerS = 1.0 / 3600.0;   // 1 deg/h/h = 1/3600 deg/h/s
constexpr double kUradToRad = 1e-6;

// Bias-instability floor factor: sigma^2 = (2 ln 2 / pi) B^2.
double FloorVariance(double b_dph) {
  return 2.0 * std::numbers::ln2 / std::numbers::pi * b_dph * b_dph;
}

// Allan variance at factor m of a unit-variance AR(1) process x_k = phi x_{k-1} + ..., with
// phi = exp(-dt / tau): (1/m^2) [m (1+phi)/(1-phi) - phi (1-phi^m)(3-phi^m)/(1-phi)^2].
// Written with u = 1 - phi and v = 1 - phi^m (both from expm1) and in long double, because the
// two terms nearly cancel when tau >> m dt.
double UnitAr1AllanVariance(double dt_s, double tau_s, std::int64_t m) {
  const long double u = -std::expm1(-static_cast<long double>(dt_s) / tau_s);
  const long double v = -std::expm1(-static_cast<long double>(dt_s) * m / tau_s);
  const long double mm = static_cast<long double>(m);
  const long double value = (mm * (2.0L - u) * u - (1.0L - u) * v * (2.0L + v)) / (u * u * mm * mm);
  return static_cast<double>(std::max(value, 0.0L));
}

// Shortest correlation time: the option, or 0.6 dt when it is 0. With 0.6 dt the sampled bank's
// Allan deviation is within about 4 % of the floor from tau = dt up (longer minimum times leave a
// deficit at short tau that biases a fitted N low; shorter ones alias into white noise).
double EffectiveTauMin(const NoiseParameters& p, double dt_s) {
  return p.bias_tau_min_s > 0.0 ? p.bias_tau_min_s : 0.6 * dt_s;
}

std::vector<double> BankTaus(const NoiseParameters& p, double dt_s) {
  const double tau_min = EffectiveTauMin(p, dt_s);
  if (!(p.bias_tau_max_s >= 100.0 * tau_min)) {
    ThrowOption("noise.bias_tau_max_s", FormatValue(p.bias_tau_max_s),
                ">= 100 x the shortest correlation time " + FormatValue(tau_min) + " s");
  }
  const double decades = std::log10(p.bias_tau_max_s / tau_min);
  const int count =
      std::max(2, static_cast<int>(std::lround(decades * p.bias_processes_per_decade)) + 1);
  std::vector<double> taus(static_cast<size_t>(count));
  for (int j = 0; j < count; ++j) {
    taus[static_cast<size_t>(j)] =
        tau_min * std::pow(p.bias_tau_max_s / tau_min, j / double(count - 1));
  }
  return taus;
}

}  // namespace

void NoiseParameters::Validate() const {
  RequireInRange("noise.quantization_urad", quantization_urad, 0.0, 1e6);
  RequireInRange("noise.arw_dpsh", arw_dpsh, 0.0, 100.0);
  RequireInRange("noise.bias_instability_dph", bias_instability_dph, 0.0, 1e4);
  RequireInRange("noise.rrw_dphpsh", rrw_dphpsh, 0.0, 1e4);
  RequireInRange("noise.rate_ramp_dphph", rate_ramp_dphph, -1e4, 1e4);
  if (bias_tau_min_s != 0.0) RequireInRange("noise.bias_tau_min_s", bias_tau_min_s, 1e-6, 1e8);
  RequireInRange("noise.bias_tau_max_s", bias_tau_max_s, 100.0 * bias_tau_min_s, 1e9);
  if (bias_processes_per_decade < 1 || bias_processes_per_decade > 20) {
    ThrowOption("noise.bias_processes_per_decade", std::to_string(bias_processes_per_decade),
                "in [1, 20]");
  }
}

BiasBank DesignBiasBank(const NoiseParameters& params, double dt_s) {
  params.Validate();
  RequirePositive("dt_s", dt_s);
  BiasBank bank;
  bank.tau_s = BankTaus(params, dt_s);
  // Flat band: a decade inside each end of the correlation-time range (the floor rolls off by
  // about 12 % at 3 tau_min and tau_max / 3), on the sample grid.
  const double lo = std::max(10.0 * EffectiveTauMin(params, dt_s), dt_s);
  const double hi = std::max(params.bias_tau_max_s / 10.0, lo);
  constexpr int kGrid = 40;
  std::vector<double> unit_avar(kGrid);
  double mean_log = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const double tau = lo * std::pow(hi / lo, i / double(kGrid - 1));
    const auto m = std::max<std::int64_t>(1, std::llround(tau / dt_s));
    double sum = 0.0;
    for (const double t : bank.tau_s) sum += UnitAr1AllanVariance(dt_s, t, m);
    unit_avar[static_cast<size_t>(i)] = sum;
    mean_log += std::log(sum) / kGrid;
  }
  const double target = FloorVariance(params.bias_instability_dph);
  const double variance = target / std::exp(mean_log);
  bank.sigma_dph = std::sqrt(variance);
  for (const double a : unit_avar) {
    bank.floor_ripple =
        std::max(bank.floor_ripple, std::abs(std::sqrt(a / std::exp(mean_log)) - 1.0));
  }
  return bank;
}

double NoiseAllanVariance(const NoiseParameters& params, double dt_s, std::int64_t m) {
  params.Validate();
  RequirePositive("dt_s", dt_s);
  if (m < 1) ThrowOption("m", std::to_string(m), ">= 1");
  const double tau = dt_s * static_cast<double>(m);
  const double q = params.quantization_urad * kUradToRad * kDegPerHourPerRadPerSecond;
  const double n = params.arw_dpsh * kArwToDphRootS;
  const double k = params.rrw_dphpsh * kRrwToDphPerRootS;
  const double r = params.rate_ramp_dphph * kRampToDphPerS;
  const double md = static_cast<double>(m);
  double avar = 3.0 * q * q / (tau * tau) + n * n / tau +
                // discrete random walk: K^2 dt (2 m^2 + 1) / (6 m) -> K^2 tau / 3
                k * k * dt_s * (2.0 * md * md + 1.0) / (6.0 * md) + 0.5 * r * r * tau * tau;
  if (params.bias_instability_dph > 0.0) {
    const BiasBank bank = DesignBiasBank(params, dt_s);
    double sum = 0.0;
    for (const double t : bank.tau_s) sum += UnitAr1AllanVariance(dt_s, t, m);
    avar += bank.sigma_dph * bank.sigma_dph * sum;
  }
  return avar;
}

Eigen::VectorXd GenerateNoise(const NoiseParameters& params, double dt_s, Eigen::Index n,
                              std::uint64_t seed) {
  params.Validate();
  RequirePositive("dt_s", dt_s);
  if (n < 0) ThrowOption("n", std::to_string(n), ">= 0");
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n);
  if (n == 0) return out;
  if (params.quantization_urad > 0.0) {
    Rng rng(seed, StreamId("quantization"));
    const double q_rad = params.quantization_urad * kUradToRad;
    const double scale = kDegPerHourPerRadPerSecond / dt_s;
    double previous = q_rad * rng.Normal();
    for (Eigen::Index k = 0; k < n; ++k) {
      const double current = q_rad * rng.Normal();
      out[k] += (current - previous) * scale;
      previous = current;
    }
  }
  if (params.arw_dpsh > 0.0) {
    Rng rng(seed, StreamId("arw"));
    const double sigma = params.arw_dpsh * kArwToDphRootS / std::sqrt(dt_s);
    for (Eigen::Index k = 0; k < n; ++k) out[k] += sigma * rng.Normal();
  }
  if (params.bias_instability_dph > 0.0) {
    Rng rng(seed, StreamId("bias-instability"));
    const BiasBank bank = DesignBiasBank(params, dt_s);
    const size_t count = bank.tau_s.size();
    std::vector<double> phi(count), drive(count), state(count);
    for (size_t j = 0; j < count; ++j) {
      phi[j] = std::exp(-dt_s / bank.tau_s[j]);
      drive[j] = bank.sigma_dph * std::sqrt(-std::expm1(-2.0 * dt_s / bank.tau_s[j]));
      state[j] = bank.sigma_dph * rng.Normal();  // start in the stationary distribution
    }
    for (Eigen::Index k = 0; k < n; ++k) {
      double sum = 0.0;
      for (size_t j = 0; j < count; ++j) {
        state[j] = phi[j] * state[j] + drive[j] * rng.Normal();
        sum += state[j];
      }
      out[k] += sum;
    }
  }
  if (params.rrw_dphpsh > 0.0) {
    Rng rng(seed, StreamId("rrw"));
    const double sigma = params.rrw_dphpsh * kRrwToDphPerRootS * std::sqrt(dt_s);
    double walk = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      walk += sigma * rng.Normal();
      out[k] += walk;
    }
  }
  if (params.rate_ramp_dphph != 0.0) {
    const double slope = params.rate_ramp_dphph * kRampToDphPerS;
    // Interval average of R t over [k dt, (k+1) dt].
    for (Eigen::Index k = 0; k < n; ++k) out[k] += slope * (static_cast<double>(k) + 0.5) * dt_s;
  }
  return out;
}

void TemperatureSensorParameters::Validate() const {
  RequireInRange("sensor.time_constant_s", time_constant_s, 0.0, 1e5);
  RequireInRange("sensor.noise_k", noise_k, 0.0, 10.0);
  RequireInRange("sensor.resolution_k", resolution_k, 0.0, 10.0);
  RequireInRange("sensor.offset_k", offset_k, -50.0, 50.0);
}

Eigen::VectorXd SenseTemperature(const TemperatureSensorParameters& params,
                                 const Eigen::VectorXd& case_c, double dt_s, std::uint64_t seed) {
  params.Validate();
  RequirePositive("dt_s", dt_s);
  Eigen::VectorXd out(case_c.size());
  if (case_c.size() == 0) return out;
  Rng rng(seed, StreamId("temperature-sensor"));
  double state = case_c[0];
  for (Eigen::Index k = 0; k < case_c.size(); ++k) {
    const double before = k > 0 ? case_c[k - 1] : case_c[0];
    state = params.time_constant_s > 0.0
                ? LagStep(state, before, case_c[k], dt_s, params.time_constant_s)
                : case_c[k];
    double reading = state + params.offset_k;
    if (params.noise_k > 0.0) reading += params.noise_k * rng.Normal();
    if (params.resolution_k > 0.0)
      reading = std::round(reading / params.resolution_k) * params.resolution_k;
    out[k] = reading;
  }
  return out;
}

}  // namespace gyrodrift::simulation
