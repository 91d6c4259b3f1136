// Validation helpers used by every Options::Validate() and public entry point, so that all
// messages share one shape: "<name> = <value>: must be <rule>".
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>

#include "gyrodrift/common/error.h"

namespace gyrodrift {

// Formats a double for messages: shortest representation that round-trips.
std::string FormatValue(double value);

// Throws UsageError unless lo <= value <= hi.
void RequireInRange(std::string_view name, double value, double lo, double hi);
// Throws UsageError unless value > 0 (and finite).
void RequirePositive(std::string_view name, double value);
// Throws UsageError unless value >= 0 (and finite).
void RequireNonNegative(std::string_view name, double value);
// Throws UsageError with "<name> = <value>: must be <rule>".
[[noreturn]] void ThrowOption(std::string_view name, std::string_view value, std::string_view rule);

// Throws DataError naming `what` unless every sample is finite and there are at least
// `min_samples` of them.
void RequireFiniteSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::Index min_samples);

// Throws DataError "<what> is constant (every sample is <v>): <consequence>" when every sample of
// x (non-empty) is equal.
void RequireVaryingSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                          std::string_view consequence);

}  // namespace gyrodrift
