// A thermal-chamber programme that gives the thermal identification (thermal_model.h) what it
// needs, for `gyrodrift plan`: the range covered, ramps both ways at two rates, dwells at three
// levels, long enough for the slowest lag state the fit can try.
//
// The programme [choice, from the fit's own warnings and advice, thermal_report.cc]: from the
// middle of the range (the unit soaked there before the log starts), heat to the top at the rate
// r; hold; cool to the middle at r/2; hold; cool to the bottom at r; hold; heat to the middle at
// r/2; hold. Four dwells of equal length at three levels (the middle twice, reached cooling and
// heating: what the hysteresis term needs), four ramps of half the range each, both directions at
// both rates. With the rate on "auto", r is 1 K/min, or faster (up to 2 K/min) where the dwells
// would otherwise be shorter than shortest_dwell_min.
#pragma once

#include <string>
#include <vector>

namespace gyrodrift::drift {

struct PlanSettings {
  double hours = 8.0;      // length of the programme, in [1, 240]
  double min_c = -20.0;    // bottom of the range, degC, in [-100, 185]
  double max_c = 60.0;     // top, in [min_c + 15, 200]: a narrower range identifies nothing
  double rate_k_per_min = 0.0;  // the faster rate r, in [0.5, 2] K/min; 0 = auto
  // The dwells' shortest length, minutes, in [10, 600] [choice: after a 1-K/min ramp the
  // simulator's case sensor still changed by 0.13 K/min 47 min after the ramp's end, above the
  // fit's ramp threshold (0.1 K/min), and a dwell counts for the fit when 10 min of it are below;
  // with 48- and 60-min dwells the fit saw 1 dwell in a plan of 8 h, with 80-min ones 4]
  double shortest_dwell_min = 80.0;
  void Validate() const;  // OptionError naming the field
};

// One step of the programme: a dwell (from_c == to_c) or a ramp.
struct PlanStep {
  double start_s = 0.0, end_s = 0.0;
  double from_c = 0.0, to_c = 0.0;
  std::string why;  // what the fit learns from it
};

struct CalibrationPlan {
  std::vector<PlanStep> steps;
  double rate_k_per_min = 0.0;  // r as chosen
  // Breakpoints (time s, set point degC) of the piecewise-linear programme, what `gyrodrift
  // simulate --profile FILE.csv` follows.
  std::vector<double> time_s, temperature_c;
  // What the plan leaves out (a programme too short for the slowest lag state the fit tries).
  std::vector<std::string> warnings;
  std::string Explanation() const;  // a few lines for the user
};

// The plan; UsageError when the settings cannot hold it (dwells shorter than
// shortest_dwell_min at 2 K/min, or at the rate asked), naming what would.
CalibrationPlan PlanCalibration(const PlanSettings& settings);

}  // namespace gyrodrift::drift
