// What a calibration run offers the thermal identification and what it lacks (thermal_model.h,
// "Calibration sufficiency"): the run's description, its warnings and the advice on what to add.
// Private to src/drift.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "../common/format.h"
#include "gyrodrift/drift/thermal_model.h"
#include "thermal_search.h"

namespace gyrodrift::drift::internal {

using gyrodrift::internal::Format;

// Ramps and dwells of every record, one after the other (a regime never spans two records).
std::vector<ThermalSegment> RecordSegments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                           double rate_hz, double ramp_rate_k_per_min,
                                           const std::vector<Eigen::Index>& record_starts);

// A coil lags its case sensor by up to about an hour (our simulator: 40 min; the family's layer
// chains: 10-60 min): a run whose slowest candidate state lags less cannot identify such a gyro.
inline constexpr double kSlowLagS = 1800.0;
// Two ramp rates of one direction differ by this factor or more to count as two rates (a plan's
// rates r and r/2 reach a case sensor as about 1.1 and 0.76 K/min in the simulator), and two
// dwells by this share of the span (at least kDistinctLevelK) to count as two levels.
inline constexpr double kDistinctRateFactor = 1.25;
inline constexpr double kDistinctLevelShare = 0.1;
inline constexpr double kDistinctLevelK = 5.0;

// Powers >= 2 of a level claim a curve between the ends of the calibrated range; the run shows
// one only where it spent this long in the middle half of channel 0's range (a dwell, or a ramp
// across it no faster than kMidRangeShare x span / 30 min). A step between two holds spends 9-26
// min there, a one-way heat-up 34-152 [choice, docs/drift.md 4.11: family units 1-60 of both].
inline constexpr double kCurveSupportS = 1800.0;
inline constexpr double kMidRangeShare = 0.5;
// A temperature span narrower than this identifies nothing beyond it (a warning); a run none of
// whose records spans it, without a ramp, is a run of holds (thermal_model.h, Structure).
inline constexpr double kShortestSpanK = 15.0;

// The distinct regimes of a run, what a calibration plan asks for (gyrodrift plan): the mean
// rates of its heating and cooling ramps (K/min, positive) and the levels of its dwells (degC);
// the time channel 0 spent in the middle kMidRangeShare of its range, s, and its widest span
// within one record, K.
struct RunRegimes {
  std::vector<double> heating_k_per_min, cooling_k_per_min, dwell_levels_c;
  double mid_range_s = 0.0;
  double widest_record_k = 0.0;
};

// Span of every channel, heating and cooling rates, ramps and dwells (channel 0 for the latter);
// returns the distinct regimes.
RunRegimes DescribeRun(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c, double rate_hz,
                       const std::vector<ThermalSegment>& segments,
                       const std::vector<Eigen::Index>& record_starts, CalibrationReport& report);

// The warnings of what the run cannot identify (`search`: what the structure search left out),
// and the advice of what to add.
void AddWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                 const SearchResult& search, const RunRegimes& regimes, CalibrationReport& report);

}  // namespace gyrodrift::drift::internal
