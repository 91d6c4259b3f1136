// The held-out folds of a thermal identification (thermal_model.h, "Structure"): equal time
// blocks, every ramp or dwell, the ends of the range. Private to src/drift.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "gyrodrift/drift/thermal_model.h"
#include "thermal_search.h"

namespace gyrodrift::drift::internal {

// The fewest logged samples a fold holds, and leaves to train on.
constexpr Eigen::Index kShortestFold = 16;

// The folds of thermal_model.h: equal time blocks (or groups of whole regimes with
// folds_at_regimes), every regime held out in turn (neighbours grouped beyond a limit), the top
// and the bottom fifth of channel 0's range. Folds with fewer than kShortestFold logged samples,
// or leaving fewer to train on, are dropped. weight: 1 logged, 0 made up.
std::vector<FoldRows> MakeFolds(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                const std::vector<ThermalSegment>& segments,
                                const Eigen::VectorXd& weight, const ThermalModelOptions& options);

}  // namespace gyrodrift::drift::internal
