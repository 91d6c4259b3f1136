// Physics-based simulator of a fibre optic gyro's output in a thermal chamber, with the truth
// (each drift part and the noise) kept apart so every drift model can be scored against it.
//
// What it computes, per output interval dt = 1 / rate_hz (sample k is the mean over
// ((k) dt, (k+1) dt], time_s = (k+1) dt, like a gyro that reports angle increments / dt):
//   chamber T_ch(t) (TemperatureProgramme) -> case T_case (first-order lag, case_time_constant_s)
//   -> winding pack, 1-D radial conduction with one ring per fibre layer (coil_thermal.h), both
//   faces coupled to the case.
//   shupe_dph  = n C / (L D) sum_l w_l dT_l/dt (winding.h; METHOD.md eq. 3 with the rate), the
//                exact interval mean because it is linear in the layer rates.
//   stress_dph = (c / D) eta [2 n mu / E_core + n^3 / (2 E_core) (P11 - mu P11 + P12 - 3 mu P12)]
//                E_coat alpha_c (T_mean(t) - T_mean(0))  (paper eq. 4 with a uniform coil). Eq. 4
//                as printed has c/D times a dimensionless index change, which would be ~3.5e3 rad/s
//                per K; the nonreciprocal share eta of the stress-induced path change is therefore
//                an explicit parameter (docs/simulation.md, "thermal stress").
//   bias_dph   = sum_i b_i (T_case - T_ref)^i: the static temperature dependence of the source,
//                detector and electronics, which sit on the case.
//   drift_dph  = shupe_dph + stress_dph + bias_dph;  noise_dph from gyro_noise.h;
//   rate_dph   = drift_dph + noise_dph + input_rate_dph (a true rate such as the Earth-rate
//                component on the sensitive axis; default 0).
//   temperature_c = a case-mounted sensor (lag, noise, resolution), the channel a user really has.
// References: Shupe, Appl. Opt. 19(5) 1980; Chen & Cui, Signal Processing 128 (2016) eqs. 1-4;
//   IEEE Std 952-1997; docs/simulation.md lists every default and its source.
// Units: SI inside (m, s, K, Pa); rates in deg/h at the interface; temperatures in degC.
// Cost: O(n_samples * substeps * layers) for the thermal part (8 h at 1 Hz, 32 layers, 4
//   substeps: about 4e6 flops) plus O(n_samples * bank size) normal draws for the noise. The
//   time loop allocates nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/simulation/coil_thermal.h"
#include "gyrodrift/simulation/gyro_noise.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/simulation/winding.h"

namespace gyrodrift::simulation {

inline constexpr double kSpeedOfLightM_S = 299792458.0;

enum class Preset { kNavigation, kTactical };
std::string_view ToString(Preset preset);        // "navigation", "tactical"
Preset PresetFromString(std::string_view name);  // throws UsageError

// Optics and geometry of the sensing coil. Defaults: navigation coil (METHOD.md sec. 1).
struct CoilParameters {
  double fibre_length_m = 1000.0;   // L, m, in [10, 1e5]
  double coil_diameter_m = 0.1;     // D, mean winding diameter, m, in [0.005, 2]
  double wavelength_m = 1310e-9;    // lambda, m, in [4e-7, 2e-6] (Sagnac scale factor)
  double refractive_index = 1.468;  // n, in [1, 2]
  double dn_dt_per_k = 1e-5;        // thermo-optic coefficient dn/dT, 1/K, in [-1e-3, 1e-3]
  double expansion_per_k = 5.5e-7;  // alpha of the fibre (silica), 1/K, in [0, 1e-4]
  // Fibre layers = rings of the conduction grid, in [20, 2000], a multiple of the pattern period.
  // Default 32: 1 km on a 0.1 m coil is 3183 turns, about 100 turns per layer of a 25 mm tall coil.
  int layers = 32;
  // Radial pitch of one layer (coated fibre diameter plus adhesive), m, in [5e-5, 2e-3].
  // Default 2.5e-4 (250 um coating): the pack is layers * pitch = 8 mm thick.
  double layer_pitch_m = 2.5e-4;
  WindingPattern winding = WindingPattern::kQuadrupole;
  // Fractional length excess of winding half A over half B, in (-0.5, 0.5); the fibre midpoint
  // moves by asymmetry * L / 2 (0.5 m for the default 1e-3 on 1 km). Ignored by the conventional
  // and symmetric patterns.
  double winding_asymmetry = 1e-3;

  ShupeConstants Shupe() const;
  // Sagnac scale factor 2 pi L D / (lambda c), rad of phase per rad/s (paper eq. 1).
  double SagnacScaleFactorS() const;
  double inner_radius_m() const { return 0.5 * coil_diameter_m - 0.5 * layers * layer_pitch_m; }
  double outer_radius_m() const { return 0.5 * coil_diameter_m + 0.5 * layers * layer_pitch_m; }
  void Validate() const;
};

// Coating thermal-stress term, paper eq. 4. Defaults: METHOD.md sec. 1 (core); the order of
// magnitude of acrylate coatings for E_coat and alpha_c [choice]; eta calibrated [choice].
struct StressParameters {
  double core_modulus_pa = 72e9;          // E_core (silica), Pa, in [1e9, 1e12]
  double poisson_ratio = 0.17;            // mu, in [0, 0.5)
  double p11 = 0.113;                     // photoelastic P11, in [-1, 1]
  double p12 = 0.252;                     // photoelastic P12, in [-1, 1]
  double coating_modulus_pa = 1e9;        // E_coating, Pa, in [1e5, 1e11]
  double coating_expansion_per_k = 1e-4;  // alpha_c, 1/K, in [0, 1e-2]
  // eta: nonreciprocal share of the stress-induced optical path change, in [0, 1e-6].
  // Default 7e-12, which gives the navigation coil 0.005 deg/h per K of mean coil temperature.
  double nonreciprocity = 7e-12;
  // Stress-free temperature of the coating (its cure temperature), degC, in [-100, 200]. The
  // stress drift follows the coil's mean temperature relative to it, so two runs that start at
  // different temperatures share one drift-versus-temperature law.
  double reference_c = 20.0;
  // The bracket of eq. 4 times E_coat alpha_c: index change per K of the coil, 1/K.
  double IndexChangePerK(double refractive_index) const;
  void Validate() const;
};

// Static bias as a polynomial in the case temperature.
struct BiasParameters {
  double reference_c = 20.0;  // T_ref, degC, in [-100, 200]
  // b_0, b_1, ...: deg/h, deg/h/K, deg/h/K^2, ...; at most 6 finite coefficients.
  // Default {0, 2e-3, 2e-5} [choice]: 0.08 deg/h + 0.032 deg/h over +-40 K.
  std::vector<double> coefficients_dph = {0.0, 2e-3, 2e-5};
  double At(double case_c) const;
  void Validate() const;
};

struct FogParameters {
  Preset preset = Preset::kNavigation;  // metadata only; the fields below are what counts
  CoilParameters coil;
  ThermalParameters thermal;
  StressParameters stress;
  BiasParameters bias;
  NoiseParameters noise;
  TemperatureSensorParameters sensor;

  // Stress drift per K of mean coil temperature change, deg/h/K.
  double StressCoefficientDphPerK() const;
  void Validate() const;  // every sub-struct; throws UsageError naming the field
};

// navigation: the defaults above. tactical: L = 200 m, D = 0.06 m, 24 layers of 0.2 mm, lighter
// case (600 s), asymmetry 3e-3, N = 0.05 deg/sqrt(h), B = 0.3 deg/h, K = 0.05 deg/h/sqrt(h),
// Q = 2 urad, larger stress and static bias (docs/simulation.md, table "presets").
FogParameters PresetParameters(Preset preset);

struct SimulationOptions {
  double duration_s = 28800.0;  // s; samples = floor(duration_s * rate_hz), in [2, 1e7]
  double rate_hz = 1.0;         // output rate, Hz, in [1e-3, 1e4]
  std::uint64_t seed = 1;       // noise and sensor streams derive from it
  double input_rate_dph = 0.0;  // true rate on the sensitive axis, deg/h, |.| <= 1e6
  bool include_noise = true;    // false: noise_dph = 0 and an ideal (noise-free) sensor reading
  Eigen::Index Samples() const;
  void Validate() const;
};

struct SimulationResult {
  // The output a user would log, and the truth. All of length `samples`.
  Eigen::VectorXd time_s, rate_dph, temperature_c;
  Eigen::VectorXd drift_dph, shupe_dph, stress_dph, bias_dph, noise_dph;
  // True temperatures at the sample times, degC.
  Eigen::VectorXd chamber_c, case_c, coil_mean_c, coil_inner_c, coil_outer_c;

  // Diagnostics.
  std::string programme;
  std::uint64_t seed = 0;
  Eigen::Index samples = 0;
  int substeps_per_sample = 0;   // conduction steps per output interval
  double conduction_step_s = 0;  // their length
  int layers = 0;
  double shupe_scale_dph_per_km2s = 0;  // deg/h per (K m^2 / s) of Shupe integral
  double stress_coefficient_dph_per_k = 0;
  double coil_lag_s = 0;        // steady-ramp lag of the mean coil temperature behind the chamber
  double bias_bank_ripple = 0;  // DesignBiasBank floor ripple (0 if B = 0)
  double max_abs_shupe_dph = 0, rms_drift_dph = 0, rms_noise_dph = 0;
  std::string Summary() const;  // one line
};

// Runs the simulation. Throws UsageError for bad parameters/options.
SimulationResult Simulate(const TemperatureProgramme& programme, const FogParameters& params,
                          const SimulationOptions& options);

}  // namespace gyrodrift::simulation
