// Errors: one exception family for the whole project.
//
// A caller's mistake (an option out of range, NaN in the input, a signal too short) throws a
// gyrodrift::Error whose message names the option or the data, the value and what is allowed.
// The kind tells the CLI which exit code to use (docs/errors.md). Numerical outcomes that are not
// mistakes (an iteration cap reached, an ill-conditioned solve) are reported in result structs,
// never thrown.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace gyrodrift {

enum class ErrorKind {
  kUsage,  // bad option or argument: exit code 2
  kData,   // the data cannot be processed (NaN, too short, missing column): exit code 3
  kIo,     // a file cannot be read or written: exit code 4
  kUnitsFailed,  // a fleet calibration ran, but a unit failed its limits or its calibration: 5
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const { return kind_; }

 private:
  ErrorKind kind_;
};

class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(ErrorKind::kUsage, message) {}
};

// An option outside what it allows, named as the library calls it (`ensemble_size`,
// `coil.winding_asymmetry`): "option = value: must be rule". The parts stay separate so the CLI
// can name the flag the user typed instead.
class OptionError : public UsageError {
 public:
  OptionError(std::string option, std::string value, std::string rule)
      : UsageError(option + " = " + value + ": must be " + rule),
        option_(std::move(option)),
        value_(std::move(value)),
        rule_(std::move(rule)) {}
  const std::string& option() const { return option_; }
  const std::string& value() const { return value_; }
  const std::string& rule() const { return rule_; }

 private:
  std::string option_, value_, rule_;
};

class DataError : public Error {
 public:
  explicit DataError(const std::string& message) : Error(ErrorKind::kData, message) {}
};

class IoError : public Error {
 public:
  explicit IoError(const std::string& message) : Error(ErrorKind::kIo, message) {}
};

// A fleet calibration that ran to the end with a unit that failed its limits or could not be
// calibrated (its outputs, fleet.csv and fleet.html are written).
class FleetFailure : public Error {
 public:
  explicit FleetFailure(const std::string& message) : Error(ErrorKind::kUnitsFailed, message) {}
};

// Exit code the CLI returns for an error of this kind.
int ExitCode(ErrorKind kind);

}  // namespace gyrodrift
