// What a calibration run offers the thermal identification and what it lacks (thermal_model.h,
// "Calibration sufficiency"): the run's description, its warnings and the advice on what to add.
// Private to src/drift.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "../common/format.h"
#include "gyrodrift/drift/thermal_model.h"

namespace gyrodrift::drift::internal {

using gyrodrift::internal::Format;

// Ramps and dwells of every record, one after the other (a regime never spans two records).
std::vector<ThermalSegment> RecordSegments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                           double rate_hz, double ramp_rate_k_per_min,
                                           const std::vector<Eigen::Index>& record_starts);

// Span of every channel, heating and cooling rates, ramps and dwells (channel 0 for the latter).
void DescribeRun(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c, double rate_hz,
                 const std::vector<ThermalSegment>& segments,
                 const std::vector<Eigen::Index>& record_starts, CalibrationReport& report);

// The warnings of what the run cannot identify, and the advice of what to add.
void AddWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                 bool fell_back_to_constant, CalibrationReport& report);

}  // namespace gyrodrift::drift::internal
