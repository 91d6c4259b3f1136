#include "gyrodrift/drift/calibration_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "../common/format.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/thermal_model.h"
#include "thermal_report.h"

namespace gyrodrift::drift {
namespace {

using gyrodrift::internal::Format;

constexpr double kAutoRate = 1.0;      // K/min
constexpr double kFastestRate = 2.0;   // K/min: faster, a coil's rate terms leave the linear range
constexpr double kSlowestRate = 0.5;   // K/min: r/2 stays a ramp for the fit (0.2 K/min and more)
constexpr int kDwells = 4;
constexpr double kNarrowestSpanK = 15.0;

}  // namespace

void PlanSettings::Validate() const {
  RequireInRange("hours", hours, 1.0, 240.0);
  // The narrowest span below the top: a bottom too high for it is the bottom's fault.
  RequireInRange("min_c", min_c, -100.0, 200.0 - kNarrowestSpanK);
  RequireInRange("max_c", max_c, min_c + kNarrowestSpanK, 200.0);
  if (rate_k_per_min != 0.0) RequireInRange("rate_k_per_min", rate_k_per_min, kSlowestRate, kFastestRate);
  RequireInRange("shortest_dwell_min", shortest_dwell_min, 10.0, 600.0);
}

CalibrationPlan PlanCalibration(const PlanSettings& settings) {
  settings.Validate();
  const double span = settings.max_c - settings.min_c;
  const double mid = 0.5 * (settings.min_c + settings.max_c);
  const double total_min = 60.0 * settings.hours;
  // Four ramps of half the span: two at r, two at r/2, 3 span / r minutes in all.
  auto dwell_min = [&](double r) { return (total_min - 3.0 * span / r) / kDwells; };
  double r = settings.rate_k_per_min;
  if (r == 0.0) {
    const double ramp_min = total_min - kDwells * settings.shortest_dwell_min;  // left for ramps
    r = ramp_min > 0.0 ? std::max(kAutoRate, 3.0 * span / ramp_min)
                       : std::numeric_limits<double>::infinity();
  }
  if (r > kFastestRate || dwell_min(r) < settings.shortest_dwell_min) {
    const double rate = std::min(r, kFastestRate);
    const double hours_needed =
        (3.0 * span / rate + kDwells * settings.shortest_dwell_min) / 60.0;
    throw UsageError(Format(
        "a plan of %.3g h cannot hold ramps over %.3g K at %.2g and %.2g K/min and %d dwells of "
        "%.0f min: it needs %.3g h or more%s",
        settings.hours, span, rate, rate / 2.0, kDwells, settings.shortest_dwell_min,
        std::ceil(hours_needed * 10.0) / 10.0,
        rate < kFastestRate
            ? Format(" (or a faster ramp rate, up to %.0f K/min)", kFastestRate).c_str()
            : ""));
  }
  const double d = 60.0 * dwell_min(r);
  CalibrationPlan plan;
  plan.rate_k_per_min = r;
  double t = 0.0, temperature = mid;
  auto dwell = [&](const std::string& why) {
    plan.steps.push_back({t, t + d, temperature, temperature, why});
    t += d;
  };
  auto ramp = [&](double to, double rate, const std::string& why) {
    const double length = std::abs(to - temperature) / rate * 60.0;
    plan.steps.push_back({t, t + length, temperature, to, why});
    t += length;
    temperature = to;
  };
  ramp(settings.max_c, r, "heating at the fast rate");
  dwell("the top: the level response at the hot end");
  ramp(mid, r / 2.0, "cooling at the slow rate (the rate terms' slope from two rates)");
  dwell("the middle after cooling (hysteresis: the same level from above)");
  ramp(settings.min_c, r, "cooling at the fast rate");
  dwell("the bottom: the level response at the cold end");
  ramp(mid, r / 2.0, "heating at the slow rate");
  dwell("the middle after heating (hysteresis: the same level from below)");
  const ThermalModelOptions fit;  // the fit's defaults: how slow a state it can try
  const std::vector<double> grid = fit.Grid(t);
  const double delay = grid.empty() ? 0.0 : fit.state_order * grid.back();
  if (delay < internal::kSlowLagS) {
    plan.warnings.push_back(Format(
        "a run of %.3g h lets the fit's thermal states lag by %.0f s at most; a coil that lags its "
        "sensor by more needs %g h or more",
        t / 3600.0, delay, fit.HoursReachingLag(internal::kSlowLagS)));
  }
  plan.time_s.push_back(0.0);
  plan.temperature_c.push_back(mid);
  for (const PlanStep& s : plan.steps) {
    plan.time_s.push_back(s.end_s);
    plan.temperature_c.push_back(s.to_c);
  }
  return plan;
}

std::string CalibrationPlan::Explanation() const {
  std::string out;
  for (const PlanStep& s : steps) {
    const std::string what =
        s.from_c == s.to_c
            ? Format("hold %.1f degC for %.0f min", s.to_c, (s.end_s - s.start_s) / 60.0)
            : Format("ramp %.1f -> %.1f degC at %.2g K/min", s.from_c, s.to_c,
                     std::abs(s.to_c - s.from_c) / (s.end_s - s.start_s) * 60.0);
    out += Format("%6.2f h  %-36s %s\n", s.start_s / 3600.0, what.c_str(), s.why.c_str());
  }
  return out;
}

}  // namespace gyrodrift::drift
