// A plausibility check of a temperature column before a model uses it: every thermal model takes
// its temperature as degC (the ramp and dwell detection in K/min, the hysteresis widths in K, the
// reference temperature, the firmware's clamp), so a column in ADC counts (a BMI270's register
// is about 64,000 at room temperature) or in kelvin is silently misread. One home for the rule
// the CLI, the fleet calibration and the Python package apply. Cost O(N).
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>

namespace gyrodrift::drift {

// Temperatures outside this range, degC, are taken for another unit [choice: the coldest space
// or polar test chambers reach -70 degC; no gyro is specified above 125 degC, nor a chamber
// above 200 degC].
inline constexpr double kPlausibleMinC = -80.0;
inline constexpr double kPlausibleMaxC = 200.0;

// "" when the finite samples of `temperature` (the column `name`) look like degC; otherwise one
// line, without the "warning: " prefix, that says what is wrong and what the tool assumes:
//   - a sample outside [kPlausibleMinC, kPlausibleMaxC] (with a hint when every sample is an
//     integer: raw ADC counts; or lies in 193..473: kelvin);
//   - every sample an integer and more than 2 distinct values, inside the range: steps of whole
//     units, as raw counts step (or a sensor read to 1 K, which makes the rate terms step-like).
// In every case the column is used as degC as given.
std::string TemperatureWarning(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                               std::string_view name);

}  // namespace gyrodrift::drift
