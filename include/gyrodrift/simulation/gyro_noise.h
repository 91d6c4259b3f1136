// Gyro sensor noise with prescribed Allan terms, and a case temperature sensor.
//
// What it computes
//   Rate noise (deg/h) whose Allan variance follows the IEEE Std 952-1997 model (METHOD.md sec. 1)
//     sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2
//   Each term has its own named random stream Rng(seed, StreamId(name)), so switching one term
//   on or off never changes the others:
//     "quantization"      Q: white angle noise e_k ~ N(0, Q^2); rate_k = (e_k - e_{k-1}) / dt.
//     "arw"               N: white rate noise of PSD N^2; per sample sigma = N / sqrt(dt).
//     "bias-instability"  B: a bank of first-order Gauss-Markov processes with log-spaced
//                         correlation times tau_j in [bias_tau_min_s, bias_tau_max_s] and equal
//                         variances: their summed PSD approximates flicker (1/f) noise, so the
//                         Allan curve has a flat floor sqrt(2 ln 2 / pi) B ~ 0.664 B (within about
//                         3 %) between 10 tau_min and tau_max / 10, rolling off outside it;
//                         the automatic tau_min = 0.6 dt extends the flat part down to tau = dt.
//                         The common variance is set from the exact
//                         Allan variance of the sampled AR(1) processes so that the floor equals
//                         the target on average (in log) over that band; the ripple is reported.
//                         (Idea: Keshner, Proc. IEEE 70(3) 1982, sums of relaxation processes.)
//     "rrw"               K: random walk of the rate, increments sigma = K sqrt(dt).
//     R                   deterministic rate ramp R t (Allan R^2 tau^2 / 2); no stream.
//   Temperature sensor (on the case, not in the coil): first-order lag, white noise from stream
//   "temperature-sensor", then rounding to the resolution.
// Units: Q in microradians, N in deg/sqrt(h), B in deg/h, K in deg/h/sqrt(h), R in deg/h/h,
//   output in deg/h; sample interval dt in s. 1 rad/s = 206264.806 deg/h.
// Cost: O(n * (4 + bank size)) normal draws; no allocation besides the output.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace gyrodrift::simulation {

inline constexpr double kDegPerHourPerRadPerSecond = 206264.80624709636;

struct NoiseParameters {
  // Quantization Q, urad, in [0, 1e6]. Default 0.786 (METHOD.md: the authors' gyro).
  double quantization_urad = 0.786;
  // Angle random walk N, deg/sqrt(h), in [0, 100]. Default 4.58e-3 (METHOD.md).
  double arw_dpsh = 4.58e-3;
  // Bias instability B, deg/h, in [0, 1e4]. Default 0.01 (METHOD.md: 0.005..0.02 [choice]).
  double bias_instability_dph = 0.01;
  // Rate random walk K, deg/h/sqrt(h), in [0, 1e4]. Default 2e-3 [choice]: its K^2 tau / 3 rises
  // above the B floor only beyond about 1e5 s, as usual for a navigation FOG.
  double rrw_dphpsh = 2e-3;
  // Rate ramp R, deg/h/h, in [-1e4, 1e4]. Default 0 (thermal drift is simulated separately).
  double rate_ramp_dphph = 0.0;
  // Correlation-time band of the bias-instability bank, s: min 0 (automatic: 0.6 x the sample
  // interval dt, which keeps the floor within about 4 % from tau = dt up) or in [1e-6, 1e8];
  // max in [100 min, 1e9]. Defaults 0 and 1e6 s: at 1 Hz a flat floor from 1 s to about 1e5 s.
  double bias_tau_min_s = 0.0;
  double bias_tau_max_s = 1e6;
  // Gauss-Markov processes per decade of the band, in [1, 20]. Default 3 (19 processes).
  int bias_processes_per_decade = 3;

  void Validate() const;  // throws UsageError "noise.<field> = <value>: must be <rule>"
};

// The bias-instability bank for one sample interval.
struct BiasBank {
  std::vector<double> tau_s;  // correlation times
  double sigma_dph = 0.0;     // standard deviation of every process
  double floor_ripple = 0.0;  // max |ADEV_bank / (0.664 B) - 1| over [10 tau_min, tau_max / 10]
};
BiasBank DesignBiasBank(const NoiseParameters& params, double dt_s);

// Exact Allan variance (deg/h)^2 at tau = m dt of the noise GenerateNoise draws at interval dt
// (the Gauss-Markov bank exactly for the sampled process; the other terms by the IEEE model).
double NoiseAllanVariance(const NoiseParameters& params, double dt_s, std::int64_t m);

// n samples of rate noise at interval dt_s, deg/h. Deterministic in (params, dt_s, n, seed).
// Throws UsageError for bad parameters.
Eigen::VectorXd GenerateNoise(const NoiseParameters& params, double dt_s, Eigen::Index n,
                              std::uint64_t seed);

struct TemperatureSensorParameters {
  // First-order time constant of the sensor and its mounting, s, in [0, 1e5]. Default 30.
  double time_constant_s = 30.0;
  // White reading noise (1 sigma), K, in [0, 10]. Default 0.02.
  double noise_k = 0.02;
  // Reading resolution, K, in [0, 10]; 0 = none. Default 0.0625 (a 12-bit digital sensor).
  double resolution_k = 0.0625;
  // Constant calibration offset, K, in [-50, 50]. Default 0.
  double offset_k = 0.0;
  void Validate() const;
};

// Sensor readings at interval dt_s of the true case temperatures case_c (sample k taken at the
// end of interval k; the case is assumed linear within an interval and at case_c[0] before it).
Eigen::VectorXd SenseTemperature(const TemperatureSensorParameters& params,
                                 const Eigen::VectorXd& case_c, double dt_s, std::uint64_t seed);

}  // namespace gyrodrift::simulation
