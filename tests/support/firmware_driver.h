// Test helper for the firmware export (io/firmware_export.h): compile a generated C header with a
// small driver and step it through a temperature record, as a user's firmware would.
#pragma once

#include <Eigen/Core>
#include <string>

namespace gyrodrift::test {

// The system C compiler found at configuration (cc, gcc or clang) and the flags a firmware header
// must compile under; the project's C++ compiler, to compile a header as C++.
inline constexpr const char* kCCompiler = GYRODRIFT_C_COMPILER;
inline constexpr const char* kCFlags =
    "-std=c99 -O2 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wshadow";
inline constexpr const char* kCxxCompiler = GYRODRIFT_CXX_COMPILER;
// Compiles a small driver (in `dir`) against the firmware header `header` (io/firmware_export.h,
// identifiers prefixed `prefix`) with `compiler` and `flags` (no -lm: the header needs no libm),
// runs it over the temperatures (N x channels, written with 17 digits) from one init and N steps,
// and returns every step's estimates (N x axes, printed with 17 digits). Compiler or run failures
// are test failures (and an empty result).
Eigen::MatrixXd RunFirmwareHeader(const std::string& header, const std::string& prefix,
                                  const Eigen::MatrixXd& temperature_c, const std::string& dir,
                                  const std::string& compiler = kCCompiler,
                                  const std::string& flags = kCFlags);

}  // namespace gyrodrift::test
