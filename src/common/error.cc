#include "gyrodrift/common/error.h"

#include <charconv>
#include <cmath>

#include "gyrodrift/common/check.h"

namespace gyrodrift {

int ExitCode(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::kUsage:
      return 2;
    case ErrorKind::kData:
      return 3;
    case ErrorKind::kIo:
      return 4;
    case ErrorKind::kUnitsFailed:
      return 5;
  }
  return 1;
}

std::string FormatValue(double value) {
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

void ThrowOption(std::string_view name, std::string_view value, std::string_view rule) {
  throw OptionError(std::string(name), std::string(value), std::string(rule));
}

void RequireInRange(std::string_view name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    ThrowOption(name, FormatValue(value), "in [" + FormatValue(lo) + ", " + FormatValue(hi) + "]");
  }
}

void RequirePositive(std::string_view name, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    ThrowOption(name, FormatValue(value), "a finite number > 0");
  }
}

void RequireNonNegative(std::string_view name, double value) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    ThrowOption(name, FormatValue(value), "a finite number >= 0");
  }
}

void RequireFiniteSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::Index min_samples) {
  if (x.size() < min_samples) {
    throw DataError(std::string(what) + " has " + std::to_string(x.size()) + " samples: at least " +
                    std::to_string(min_samples) + " are needed");
  }
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    // NaN fails the comparison too, so only a bad sample pays for the call.
    if (!(std::fabs(x[i]) <= kLargestSampleMagnitude)) RequireUsableSample(what, i + 1, x[i]);
  }
}

void RequireUsableSample(std::string_view what, Eigen::Index number, double value, bool logged) {
  if (std::isfinite(value) && std::fabs(value) <= kLargestSampleMagnitude) return;
  const std::string sample = std::string(what) + " sample " + std::to_string(number) +
                             (logged ? " (logged)" : "") + " is " + FormatValue(value);
  if (!std::isfinite(value)) {
    throw DataError(sample + ": every " + (logged ? "logged " : "") + "sample must be finite");
  }
  throw DataError(sample + ": no instrument logs a magnitude above " +
                  FormatValue(kLargestSampleMagnitude) +
                  " (the models' sums of squares would overflow)");
}

void RequireVaryingSignal(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                          std::string_view consequence) {
  if (x.size() == 0) return;
  if (!(x.array() != x[0]).any()) {
    throw DataError(std::string(what) + " is constant (every sample is " + FormatValue(x[0]) +
                    "): " + std::string(consequence));
  }
  // The mirror of kLargestSampleMagnitude: no instrument logs only magnitudes this small, and
  // their squares underflow to 0 (a decomposition's scaling by the std gave NaN, exit 0).
  constexpr double kSmallestLargestMagnitude = 1e-100;
  const double largest = x.cwiseAbs().maxCoeff();
  if (!(largest < kSmallestLargestMagnitude)) return;
  throw DataError(std::string(what) + " varies only below " +
                  FormatValue(kSmallestLargestMagnitude) + " in magnitude (its largest sample is " +
                  FormatValue(largest) + "): its squares underflow to 0; rescale it");
}

}  // namespace gyrodrift
