#include "gyrodrift/simulation/temperature_programme.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Chamber air in a sane range; also catches Kelvin or Fahrenheit columns fed in by mistake.
constexpr double kMinC = -100.0;
constexpr double kMaxC = 200.0;

std::string Fmt(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", v);
  return buffer;
}

}  // namespace

TemperatureProgramme TemperatureProgramme::FromSegments(
    double start_c, const std::vector<ProgrammeSegment>& segments, std::string name) {
  RequireInRange("start_c", start_c, kMinC, kMaxC);
  if (segments.empty()) ThrowOption("segments", "[]", "at least one segment");
  TemperatureProgramme p;
  p.kind_ = Kind::kPiecewiseLinear;
  p.name_ = std::move(name);
  p.mean_c_ = p.amplitude_c_ = p.period_s_ = p.phase_rad_ = kNaN;
  p.time_s_.push_back(0.0);
  p.temperature_c_.push_back(start_c);
  for (size_t i = 0; i < segments.size(); ++i) {
    const auto& s = segments[i];
    const std::string prefix = "segments[" + std::to_string(i) + "].";
    RequirePositive(prefix + "duration_s", s.duration_s);
    double next = p.temperature_c_.back();
    if (s.kind == ProgrammeSegment::Kind::kRamp) {
      RequireInRange(prefix + "target_c", s.target_c, kMinC, kMaxC);
      next = s.target_c;
    }
    p.time_s_.push_back(p.time_s_.back() + s.duration_s);
    p.temperature_c_.push_back(next);
  }
  return p;
}

TemperatureProgramme TemperatureProgramme::FromSamples(const Eigen::VectorXd& time_s,
                                                       const Eigen::VectorXd& temperature_c,
                                                       std::string name) {
  if (time_s.size() != temperature_c.size()) {
    throw DataError(name + ": " + std::to_string(time_s.size()) + " times but " +
                    std::to_string(temperature_c.size()) + " temperatures");
  }
  RequireFiniteSignal(name + " time_s", time_s, 2);
  RequireFiniteSignal(name + " temperature_c", temperature_c, 2);
  for (Eigen::Index i = 1; i < time_s.size(); ++i) {
    if (!(time_s[i] > time_s[i - 1])) {
      throw DataError(name + " time_s row " + std::to_string(i + 1) + " is " +
                      FormatValue(time_s[i]) + " after " + FormatValue(time_s[i - 1]) +
                      ": times must strictly increase");
    }
  }
  // The run starts at 0 s: a profile that ends there would give a run of no length.
  if (time_s.size() > 0 && !(time_s[time_s.size() - 1] > 0.0)) {
    throw DataError(name + " time_s ends at " + FormatValue(time_s[time_s.size() - 1]) +
                    " s: a profile's times are seconds from the start of the run, which is 0");
  }
  for (Eigen::Index i = 0; i < temperature_c.size(); ++i) {
    if (temperature_c[i] < kMinC || temperature_c[i] > kMaxC) {
      throw DataError(name + " temperature_c row " + std::to_string(i + 1) + " is " +
                      FormatValue(temperature_c[i]) + ": must be in [-100, 200] degC");
    }
  }
  TemperatureProgramme p;
  p.kind_ = Kind::kPiecewiseLinear;
  p.name_ = std::move(name);
  p.mean_c_ = p.amplitude_c_ = p.period_s_ = p.phase_rad_ = kNaN;
  p.time_s_.assign(time_s.data(), time_s.data() + time_s.size());
  p.temperature_c_.assign(temperature_c.data(), temperature_c.data() + temperature_c.size());
  return p;
}

TemperatureProgramme TemperatureProgramme::Sine(double mean_c, double amplitude_c, double period_s,
                                                double phase_rad, std::string name) {
  RequireInRange("sine.mean_c", mean_c, kMinC, kMaxC);
  RequireNonNegative("sine.amplitude_c", amplitude_c);
  if (mean_c - amplitude_c < kMinC || mean_c + amplitude_c > kMaxC) {
    ThrowOption("sine.amplitude_c", FormatValue(amplitude_c),
                "such that mean +- amplitude stays in [-100, 200] degC");
  }
  RequirePositive("sine.period_s", period_s);
  RequireInRange("sine.phase_rad", phase_rad, -1e6, 1e6);
  TemperatureProgramme p;
  p.kind_ = Kind::kSine;
  p.name_ = std::move(name);
  p.mean_c_ = mean_c;
  p.amplitude_c_ = amplitude_c;
  p.period_s_ = period_s;
  p.phase_rad_ = phase_rad;
  return p;
}

double TemperatureProgramme::TemperatureAt(double t_s) const {
  if (kind_ == Kind::kSine) {
    return mean_c_ + amplitude_c_ * std::sin(2.0 * std::numbers::pi * t_s / period_s_ + phase_rad_);
  }
  if (t_s <= time_s_.front()) return temperature_c_.front();
  if (t_s >= time_s_.back()) return temperature_c_.back();
  const auto it = std::upper_bound(time_s_.begin(), time_s_.end(), t_s);
  const size_t i = static_cast<size_t>(it - time_s_.begin());  // time_s_[i-1] <= t < time_s_[i]
  const double f = (t_s - time_s_[i - 1]) / (time_s_[i] - time_s_[i - 1]);
  return temperature_c_[i - 1] + f * (temperature_c_[i] - temperature_c_[i - 1]);
}

double TemperatureProgramme::NominalDuration() const {
  return kind_ == Kind::kSine ? period_s_ : time_s_.back();
}

double TemperatureProgramme::DefaultSimulationDuration() const {
  return kind_ == Kind::kSine ? 8 * 3600.0 : NominalDuration();
}

double TemperatureProgramme::MaxRateKPerS() const {
  if (kind_ == Kind::kSine) return 2.0 * std::numbers::pi * amplitude_c_ / period_s_;
  double r = 0.0;
  for (size_t i = 1; i < time_s_.size(); ++i) {
    r = std::max(
        r, std::abs(temperature_c_[i] - temperature_c_[i - 1]) / (time_s_[i] - time_s_[i - 1]));
  }
  return r;
}

std::string TemperatureProgramme::Summary() const {
  if (kind_ == Kind::kSine) {
    return name_ + ": sine " + Fmt(mean_c_) + " +- " + Fmt(amplitude_c_) + " degC, period " +
           Fmt(period_s_) + " s, max " + Fmt(MaxRateKPerS()) + " K/s";
  }
  const auto [lo, hi] = std::minmax_element(temperature_c_.begin(), temperature_c_.end());
  return name_ + ": " + std::to_string(time_s_.size()) + " breakpoints over " +
         Fmt(time_s_.back() - time_s_.front()) + " s, " + Fmt(*lo) + ".." + Fmt(*hi) +
         " degC, max " + Fmt(MaxRateKPerS()) + " K/s";
}

TemperatureProgramme BuiltinProgramme(std::string_view name) {
  using K = ProgrammeSegment::Kind;
  constexpr double kMin = 60.0;
  if (name == "chamber") {
    // 1 K/min is the customary ramp rate of gyro thermal tests: fast enough to excite the Shupe
    // term, slow enough for the chamber air to follow.
    return TemperatureProgramme::FromSegments(20.0,
                                              {{K::kDwell, 30 * kMin, 0.0},
                                               {K::kRamp, 40 * kMin, 60.0},
                                               {K::kDwell, 90 * kMin, 0.0},
                                               {K::kRamp, 80 * kMin, -20.0},
                                               {K::kDwell, 90 * kMin, 0.0},
                                               {K::kRamp, 40 * kMin, 20.0},
                                               {K::kDwell, 110 * kMin, 0.0}},
                                              "chamber");
  }
  if (name == "chamber-b") {
    // Different levels, rates and order, so a model trained on "chamber" meets new histories.
    return TemperatureProgramme::FromSegments(25.0,
                                              {{K::kDwell, 20 * kMin, 0.0},
                                               {K::kRamp, 40 * kMin, 45.0},
                                               {K::kDwell, 60 * kMin, 0.0},
                                               {K::kRamp, 60 * kMin, 0.0},
                                               {K::kDwell, 75 * kMin, 0.0},
                                               {K::kRamp, 70 * kMin, 35.0},
                                               {K::kDwell, 60 * kMin, 0.0},
                                               {K::kRamp, 40 * kMin, 15.0},
                                               {K::kDwell, 55 * kMin, 0.0}},
                                              "chamber-b");
  }
  if (name == "sine") return TemperatureProgramme::Sine(20.0, 20.0, 7200.0, 0.0, "sine");
  ThrowOption("profile", std::string(name), "one of chamber, chamber-b, sine (or a CSV file)");
}

std::vector<std::string> BuiltinProgrammeNames() { return {"chamber", "chamber-b", "sine"}; }

}  // namespace gyrodrift::simulation
