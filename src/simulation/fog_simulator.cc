#include "gyrodrift/simulation/fog_simulator.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

constexpr gyrodrift::internal::EnumNames<Preset, 2> kPresets{{
    {Preset::kNavigation, "navigation"},
    {Preset::kTactical, "tactical"},
}};

}  // namespace

std::string_view ToString(Preset preset) { return gyrodrift::internal::EnumName(preset, kPresets); }

Preset PresetFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "preset", kPresets);
}

ShupeConstants CoilParameters::Shupe() const {
  return {.refractive_index = refractive_index,
          .dn_dt_per_k = dn_dt_per_k,
          .expansion_per_k = expansion_per_k,
          .fibre_length_m = fibre_length_m,
          .coil_diameter_m = coil_diameter_m};
}

double CoilParameters::SagnacScaleFactorS() const {
  return 2.0 * std::numbers::pi * fibre_length_m * coil_diameter_m /
         (wavelength_m * kSpeedOfLightM_S);
}

void CoilParameters::Validate() const {
  RequireInRange("coil.fibre_length_m", fibre_length_m, 10.0, 1e5);
  RequireInRange("coil.coil_diameter_m", coil_diameter_m, 0.005, 2.0);
  RequireInRange("coil.wavelength_m", wavelength_m, 4e-7, 2e-6);
  RequireInRange("coil.refractive_index", refractive_index, 1.0, 2.0);
  RequireInRange("coil.dn_dt_per_k", dn_dt_per_k, -1e-3, 1e-3);
  RequireInRange("coil.expansion_per_k", expansion_per_k, 0.0, 1e-4);
  const int period = PatternPeriod(winding);
  if (layers < 20 || layers > 2000 || layers % period != 0) {
    ThrowOption("coil.layers", std::to_string(layers),
                "in [20, 2000] and a multiple of " + std::to_string(period) + " for a " +
                    std::string(ToString(winding)) + " winding");
  }
  RequireInRange("coil.layer_pitch_m", layer_pitch_m, 5e-5, 2e-3);
  if (!(inner_radius_m() >= 0.1 * coil_diameter_m)) {
    ThrowOption("coil.layer_pitch_m", FormatValue(layer_pitch_m),
                "such that the pack (layers * pitch = " + FormatValue(layers * layer_pitch_m) +
                    " m) is at most 0.8 x the coil diameter");
  }
  if (!(std::abs(winding_asymmetry) < 0.5)) {
    ThrowOption("coil.winding_asymmetry", FormatValue(winding_asymmetry), "in (-0.5, 0.5)");
  }
}

double StressParameters::IndexChangePerK(double n) const {
  const double mu = poisson_ratio;
  const double bracket =
      2.0 * n * mu / core_modulus_pa +
      n * n * n / (2.0 * core_modulus_pa) * (p11 - mu * p11 + p12 - 3.0 * mu * p12);
  return bracket * coating_modulus_pa * coating_expansion_per_k;
}

void StressParameters::Validate() const {
  RequireInRange("stress.core_modulus_pa", core_modulus_pa, 1e9, 1e12);
  RequireInRange("stress.poisson_ratio", poisson_ratio, 0.0, 0.4999);
  RequireInRange("stress.p11", p11, -1.0, 1.0);
  RequireInRange("stress.p12", p12, -1.0, 1.0);
  RequireInRange("stress.coating_modulus_pa", coating_modulus_pa, 1e5, 1e11);
  RequireInRange("stress.coating_expansion_per_k", coating_expansion_per_k, 0.0, 1e-2);
  RequireInRange("stress.nonreciprocity", nonreciprocity, 0.0, 1e-6);
  RequireInRange("stress.reference_c", reference_c, -100.0, 200.0);
}

double BiasParameters::At(double case_c) const {
  const double dt = case_c - reference_c;
  double value = 0.0;
  for (auto it = coefficients_dph.rbegin(); it != coefficients_dph.rend(); ++it) {
    value = value * dt + *it;  // Horner
  }
  return value;
}

void BiasParameters::Validate() const {
  RequireInRange("bias.reference_c", reference_c, -100.0, 200.0);
  if (coefficients_dph.size() > 6) {
    ThrowOption("bias.coefficients_dph", std::to_string(coefficients_dph.size()) + " values",
                "at most 6 values");
  }
  for (size_t i = 0; i < coefficients_dph.size(); ++i) {
    RequireInRange("bias.coefficients_dph[" + std::to_string(i) + "]", coefficients_dph[i], -1e6,
                   1e6);
  }
}

double FogParameters::StressCoefficientDphPerK() const {
  return kSpeedOfLightM_S / coil.coil_diameter_m * stress.nonreciprocity *
         stress.IndexChangePerK(coil.refractive_index) * kDegPerHourPerRadPerSecond;
}

void FogParameters::Validate() const {
  coil.Validate();
  thermal.Validate();
  stress.Validate();
  bias.Validate();
  noise.Validate();
  sensor.Validate();
}

FogParameters PresetParameters(Preset preset) {
  FogParameters p;
  p.preset = preset;
  if (preset == Preset::kNavigation) return p;
  // Tactical grade: short fibre on a small coil, thinner fibre, lighter housing, looser winding
  // control, more noise.
  p.coil.fibre_length_m = 200.0;
  p.coil.coil_diameter_m = 0.06;
  p.coil.layers = 24;
  p.coil.layer_pitch_m = 2.0e-4;
  p.coil.winding_asymmetry = 3e-3;
  p.thermal.case_time_constant_s = 600.0;
  p.thermal.outer_conductance_w_m2k = 10.0;
  p.thermal.inner_conductance_w_m2k = 4.0;
  p.stress.nonreciprocity = 2e-11;
  p.bias.coefficients_dph = {0.0, 0.02, 2e-4};
  p.noise.quantization_urad = 2.0;
  p.noise.arw_dpsh = 0.05;
  p.noise.bias_instability_dph = 0.3;
  p.noise.rrw_dphpsh = 0.05;
  p.sensor.noise_k = 0.05;
  return p;
}

Eigen::Index SimulationOptions::Samples() const {
  return static_cast<Eigen::Index>(std::floor(duration_s * rate_hz * (1.0 + 1e-12)));
}

void SimulationOptions::Validate() const {
  RequireInRange("rate_hz", rate_hz, 1e-3, 1e4);
  RequirePositive("duration_s", duration_s);
  const double samples = std::floor(duration_s * rate_hz * (1.0 + 1e-12));
  // 1e7 samples keep the result (13 vectors) near 1 GB and the CLI's CSV text near 1.3 GB.
  if (!(samples >= 2.0 && samples <= 1e7)) {
    ThrowOption("duration_s", FormatValue(duration_s) + " s",
                "such that duration * rate gives between 2 and 1e7 samples (rate " +
                    FormatValue(rate_hz) + " Hz)");
  }
  RequireInRange("input_rate_dph", input_rate_dph, -1e6, 1e6);
}

std::string SimulationResult::Summary() const {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer),
                "simulated %lld samples on %s (seed %llu): coil lag %.0f s, max |shupe| %.3g "
                "deg/h, rms drift %.3g deg/h, rms noise %.3g deg/h, %d layers x %d substeps of "
                "%.3g s",
                static_cast<long long>(samples), programme.c_str(),
                static_cast<unsigned long long>(seed), coil_lag_s, max_abs_shupe_dph, rms_drift_dph,
                rms_noise_dph, layers, substeps_per_sample, conduction_step_s);
  return buffer;
}

namespace {

// The result's description of the run (everything but the series), with its n-sample series
// allocated.
SimulationResult DescribeRun(const TemperatureProgramme& programme, const FogParameters& params,
                             const SimulationOptions& options, const RadialConduction& pack) {
  const Eigen::Index n = options.Samples();
  const double dt = 1.0 / options.rate_hz;
  SimulationResult r;
  r.programme = programme.name();
  r.seed = options.seed;
  r.samples = n;
  r.layers = params.coil.layers;
  r.substeps_per_sample =
      static_cast<int>(std::ceil(dt / params.thermal.max_step_s * (1.0 - 1e-12)));
  r.conduction_step_s = dt / r.substeps_per_sample;
  r.shupe_scale_dph_per_km2s = params.coil.Shupe().Scale() * kDegPerHourPerRadPerSecond;
  r.stress_coefficient_dph_per_k = params.StressCoefficientDphPerK();
  r.coil_lag_s = params.thermal.case_time_constant_s + pack.RampLagSeconds();
  for (Eigen::VectorXd* v : {&r.time_s, &r.rate_dph, &r.temperature_c, &r.drift_dph, &r.shupe_dph,
                             &r.stress_dph, &r.bias_dph, &r.noise_dph, &r.chamber_c, &r.case_c,
                             &r.coil_mean_c, &r.coil_inner_c, &r.coil_outer_c}) {
    v->resize(n);
  }
  return r;
}

// The chamber, case and coil temperatures sample by sample, and the drift they cause (Shupe,
// stress, bias), into r (sized by DescribeRun).
void SimulateThermalDrift(const TemperatureProgramme& programme, const FogParameters& params,
                          const WindingMap& winding, double dt, RadialConduction& pack,
                          SimulationResult& r) {
  const Eigen::Index n = r.samples;
  const int layers = params.coil.layers;
  const double shupe_scale = r.shupe_scale_dph_per_km2s;
  const double stress_per_k = r.stress_coefficient_dph_per_k;
  const double tau_case = params.thermal.case_time_constant_s;
  // The run starts in equilibrium with the chamber. The pack is solved for the deviation from
  // that start temperature, so a constant chamber leaves it at exactly zero (no round-off drift).
  double chamber = programme.TemperatureAt(0.0);
  const double start_c = chamber;
  // Coil mean temperature relative to the coating's stress-free temperature at the start.
  const double start_offset = start_c - params.stress.reference_c;
  double case_c = chamber;
  pack.SetUniform(0.0);
  Eigen::VectorXd previous = pack.temperature_c();
  const Eigen::VectorXd& weights = winding.shupe_weight_m2;
  const int substeps = r.substeps_per_sample;
  const double h = r.conduction_step_s;

  for (Eigen::Index k = 0; k < n; ++k) {
    for (int s = 1; s <= substeps; ++s) {
      const double t = (static_cast<double>(k) + static_cast<double>(s) / substeps) * dt;
      const double chamber_new = programme.TemperatureAt(t);
      const double case_new = LagStep(case_c, chamber, chamber_new, h, tau_case);
      pack.Step(h, case_c - start_c, case_new - start_c, case_c - start_c, case_new - start_c);
      chamber = chamber_new;
      case_c = case_new;
    }
    const Eigen::VectorXd& layer_t = pack.temperature_c();
    // Shupe integral of the mean layer rates over the interval: sum w_l (T_l - T_l_prev) / dt.
    double integral = 0.0;
    for (int l = 0; l < layers; ++l) integral += weights[l] * (layer_t[l] - previous[l]);
    previous = layer_t;
    const double mean_change = pack.MeanTemperature();
    r.time_s[k] = static_cast<double>(k + 1) * dt;
    r.shupe_dph[k] = shupe_scale * integral / dt;
    r.stress_dph[k] = stress_per_k * (start_offset + mean_change);
    r.bias_dph[k] = params.bias.At(case_c);
    r.chamber_c[k] = chamber;
    r.case_c[k] = case_c;
    r.coil_mean_c[k] = start_c + mean_change;
    r.coil_inner_c[k] = start_c + layer_t[0];
    r.coil_outer_c[k] = start_c + layer_t[layers - 1];
  }
  r.drift_dph = r.shupe_dph + r.stress_dph + r.bias_dph;
}

// The gyro's noise and the temperature sensor's reading (ideal ones without noise), then the
// logged rate.
void AddNoiseAndReadings(const FogParameters& params, const SimulationOptions& options, double dt,
                         SimulationResult& r) {
  const Eigen::Index n = r.samples;
  if (options.include_noise) {
    r.noise_dph = GenerateNoise(params.noise, dt, n, options.seed);
    r.temperature_c = SenseTemperature(params.sensor, r.case_c, dt, options.seed);
    if (params.noise.bias_instability_dph > 0.0) {
      r.bias_bank_ripple = DesignBiasBank(params.noise, dt).floor_ripple;
    }
  } else {
    r.noise_dph.setZero();
    TemperatureSensorParameters ideal = params.sensor;
    ideal.noise_k = 0.0;
    ideal.resolution_k = 0.0;
    r.temperature_c = SenseTemperature(ideal, r.case_c, dt, options.seed);
  }
  r.rate_dph = r.drift_dph + r.noise_dph;
  r.rate_dph.array() += options.input_rate_dph;
}

}  // namespace

SimulationResult Simulate(const TemperatureProgramme& programme, const FogParameters& params,
                          const SimulationOptions& options) {
  params.Validate();
  options.Validate();
  const double dt = 1.0 / options.rate_hz;
  const auto& coil = params.coil;
  RadialConduction pack(coil.inner_radius_m(), coil.outer_radius_m(), coil.layers, params.thermal);
  // Same number of turns in every layer: the fibre a layer holds grows with its radius.
  const WindingMap winding = BuildWinding(coil.winding, coil.layers, coil.fibre_length_m,
                                          coil.winding_asymmetry, pack.cell_radius_m());
  SimulationResult r = DescribeRun(programme, params, options, pack);
  SimulateThermalDrift(programme, params, winding, dt, pack, r);
  AddNoiseAndReadings(params, options, dt, r);
  const double n = static_cast<double>(r.samples);
  r.max_abs_shupe_dph = r.shupe_dph.cwiseAbs().maxCoeff();
  r.rms_drift_dph = std::sqrt(r.drift_dph.squaredNorm() / n);
  r.rms_noise_dph = std::sqrt(r.noise_dph.squaredNorm() / n);
  return r;
}

}  // namespace gyrodrift::simulation
