// Shared test helpers: paths to the external reference data and the built CLI, CSV fixtures,
// the portable generators the reference fixtures were made with, and running the CLI.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/html/report.h"

namespace gyrodrift::test {

// ../shared/testdata/<relative>
std::string TestDataPath(const std::string& relative);
// A fresh empty directory for this test (under the build tree), unique per running test.
std::string TempDir(const std::string& name);
// Matrix of every numeric column of a CSV file with a header (rows x columns).
Eigen::MatrixXd ReadCsvMatrix(const std::string& path, std::vector<std::string>* header = nullptr);
// Raw little-endian float64 file.
Eigen::VectorXd ReadF64(const std::string& path);

// Lehmer / Park-Miller minimal-standard LCG, s <- 16807 s mod (2^31 - 1); u = s / (2^31 - 1).
class LehmerUniform {
 public:
  explicit LehmerUniform(std::int64_t seed) : state_(seed) {}
  double Next();

 private:
  std::int64_t state_;
};
// First n Box-Muller normals of a Lehmer stream (cos, sin, cos, sin, ...), as the ICEEMDAN
// fixture SOURCE.md defines them.
Eigen::VectorXd LehmerBoxMullerNormals(std::int64_t seed, Eigen::Index n);

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs the built gyrodrift binary with the given argument string (shell-quoted by the caller).
CommandResult RunCli(const std::string& args);
// Runs a shell command line (quoted by the caller), stdin from /dev/null.
CommandResult RunShell(const std::string& command_line);

// A small thermal log for the CLI tests, one row per `step_s` seconds: time_s, rate_dph = drift +
// white noise (0.02), temperature_c (1.5 cycles of 20 +- 15 degC), drift_dph (the truth: a
// first-order lag of the temperature, tau 40 samples, and its rate).
std::string ThermalLogCsv(int n, std::uint64_t seed, double step_s = 1.0);
bool FileExists(const std::string& path);

// `text` with every occurrence of each placeholder key replaced by its value.
std::string Substitute(std::string text,
                       const std::vector<std::pair<std::string, std::string>>& placeholders);
// Asserts that a CLI run failed cleanly: the exit code, exactly one stderr line
// "gyrodrift: error: ..." containing `message`, and neither `output` nor `output`.json left
// behind. `label` names the case in failure messages.
void ExpectCleanFailure(const CommandResult& result, int exit_code, const std::string& message,
                        const std::string& output, const std::string& label);

// Stand-in for dygraphs (the size of the real script, no function): for tests of a page's
// composition, not of the package.
html::DygraphsAssets FakeDygraphs();

}  // namespace gyrodrift::test
