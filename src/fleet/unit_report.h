// The HTML page of one calibrated unit (OUT/<serial>/report.html).
#pragma once

#include <string>

#include "gyrodrift/fleet/calibration.h"

namespace gyrodrift::fleet {

// Per axis: the model, the verification runs' block means before and after compensation (with
// the true drift when there is one), the Allan deviation before and after, and the figures that
// go into fleet.csv, with the limits each breaks.
std::string RenderUnitReport(const Manifest& manifest, const UnitSpec& spec,
                             const UnitResult& unit, const html::DygraphsAssets& assets);

// Flags, per axis across the fleet, the rows whose figures are outliers (fleet_rows.cc).
void FlagOutliers(std::vector<FleetRow>& rows);

}  // namespace gyrodrift::fleet
