// Thermal-chamber temperature programmes: the air temperature T_ch(t) a gyro is exposed to.
//
// What it computes
//   A programme is either piecewise linear (built from ramp/dwell segments or from measured
//   (time, temperature) samples; held constant after the last breakpoint) or a sine. Two built-in
//   8-hour chamber programmes ("chamber" for training, "chamber-b" for testing a model on a
//   different history) and a sine programme are provided; docs/simulation.md tabulates them.
// Units: time in seconds from the start of the run, temperature in degrees Celsius, rates in K/s.
// Cost: TemperatureAt is O(log B) for B breakpoints (binary search), O(1) for a sine.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

namespace gyrodrift::simulation {

// One step of a ramp/dwell programme.
struct ProgrammeSegment {
  enum class Kind { kDwell, kRamp };
  Kind kind = Kind::kDwell;
  // Length of the segment in s, finite and > 0.
  double duration_s = 0.0;
  // kRamp: temperature reached at the end of the segment (linear ramp from the previous value),
  // degC, in [-100, 200]. Ignored for kDwell.
  double target_c = 0.0;
};

class TemperatureProgramme {
 public:
  enum class Kind { kPiecewiseLinear, kSine };

  // Ramp/dwell programme starting at start_c. Throws UsageError naming the bad segment.
  static TemperatureProgramme FromSegments(double start_c,
                                           const std::vector<ProgrammeSegment>& segments,
                                           std::string name = "segments");
  // Measured or hand-made samples, linearly interpolated; before the first sample the first value
  // holds, after the last the last value holds. Throws DataError unless there are >= 2 samples,
  // every value is finite, times strictly increase and temperatures are in [-100, 200] degC.
  static TemperatureProgramme FromSamples(const Eigen::VectorXd& time_s,
                                          const Eigen::VectorXd& temperature_c,
                                          std::string name = "samples");
  // T(t) = mean_c + amplitude_c * sin(2 pi t / period_s + phase_rad). Throws UsageError.
  static TemperatureProgramme Sine(double mean_c, double amplitude_c, double period_s,
                                   double phase_rad = 0.0, std::string name = "sine");

  // Chamber temperature at time t (s), degC.
  double TemperatureAt(double t_s) const;
  // Length of the defined part (last breakpoint time, or one period for a sine), s.
  double NominalDuration() const;
  // The length to simulate when none is asked (`gyrodrift simulate`, Python's simulate): the
  // defined part, or 8 h for a sine (one period is too short to see a drift), s.
  double DefaultSimulationDuration() const;
  Kind kind() const { return kind_; }
  const std::string& name() const { return name_; }
  // Breakpoints of a piecewise-linear programme (empty for a sine).
  const std::vector<double>& breakpoint_time_s() const { return time_s_; }
  const std::vector<double>& breakpoint_temperature_c() const { return temperature_c_; }
  // Sine parameters (NaN for a piecewise-linear programme).
  double sine_mean_c() const { return mean_c_; }
  double sine_amplitude_c() const { return amplitude_c_; }
  double sine_period_s() const { return period_s_; }
  double sine_phase_rad() const { return phase_rad_; }
  // Largest |dT/dt| of the programme, K/s.
  double MaxRateKPerS() const;
  // One line, e.g. "chamber: 8 breakpoints over 28800 s, 20..60..-20 degC, max 0.0167 K/s".
  std::string Summary() const;

 private:
  Kind kind_ = Kind::kPiecewiseLinear;
  std::string name_;
  std::vector<double> time_s_, temperature_c_;
  double mean_c_, amplitude_c_, period_s_, phase_rad_;
};

// The built-in programmes, by name: "chamber", "chamber-b", "sine".
//   chamber   (8 h): dwell 20 degC 30 min; ramp to 60 degC at 1 K/min; dwell 90 min; ramp to
//             -20 degC at 1 K/min; dwell 90 min; ramp to 20 degC at 1 K/min; dwell 110 min.
//   chamber-b (8 h): dwell 25 degC 20 min; ramp to 45 degC at 0.5 K/min; dwell 60 min; ramp to
//             0 degC at 0.75 K/min; dwell 75 min; ramp to 35 degC at 0.5 K/min; dwell 60 min;
//             ramp to 15 degC at 0.5 K/min; dwell 55 min.
//   sine:     20 degC +- 20 degC, period 2 h (slowest slope 0, steepest 0.0175 K/s).
TemperatureProgramme BuiltinProgramme(std::string_view name);
// Names BuiltinProgramme accepts, for help texts and messages.
std::vector<std::string> BuiltinProgrammeNames();

}  // namespace gyrodrift::simulation
