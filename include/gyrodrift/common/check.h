// Validation helpers used by every Options::Validate() and public entry point, so that all
// messages share one shape: "<name> = <value>: must be <rule>".
#pragma once

#include <Eigen/Core>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

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

// Runs validate(), the Validate() of an options struct held in field `field` of another: an
// OptionError from it is thrown again with its option named by the dotted path
// ("sifting.max_sifts"), so every refusal names the field as a caller reaches it.
template <class Validate>
void ValidateNested(std::string_view field, Validate&& validate) {
  try {
    validate();
  } catch (const OptionError& e) {
    throw OptionError(std::string(field) + "." + e.option(), e.value(), e.rule());
  }
}

// Runs validate(), the Validate() of options derived from a flat settings struct (a front end's
// names for some of their fields): an OptionError naming one of the derived fields (`names`: field
// path, setting) is thrown again naming the setting, so a refusal names what the caller set.
template <class Validate>
void ValidateAsSettings(std::initializer_list<std::pair<std::string_view, std::string_view>> names,
                        Validate&& validate) {
  try {
    validate();
  } catch (const OptionError& e) {
    for (const auto& [field, setting] : names) {
      if (e.option() == field) throw OptionError(std::string(setting), e.value(), e.rule());
    }
    throw;
  }
}

// The largest sample magnitude a signal may hold: no instrument logs more, and the sums of
// squares and the powers the models take of larger values overflow (1e200 gave inf and NaN
// results with exit 0 before this bound).
inline constexpr double kLargestSampleMagnitude = 1e100;

// Throws DataError naming `what` and its 1-based sample `number` ("sample 7 (logged)" for a
// logged row of a log with made-up rows) unless value is finite and at most
// kLargestSampleMagnitude in magnitude.
void RequireUsableSample(std::string_view what, Eigen::Index number, double value,
                         bool logged = false);

// Throws DataError naming `what` unless there are at least `min_samples` samples, each usable
// (RequireUsableSample).
void RequireFiniteSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::Index min_samples);

// Throws DataError "<what> is constant (every sample is <v>): <consequence>" when every sample of
// x (non-empty) is equal.
void RequireVaryingSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                          std::string_view consequence);

}  // namespace gyrodrift
