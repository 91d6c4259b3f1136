#include "support/test_support.h"

#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <gtest/gtest.h>

#include "gyrodrift/common/random.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::test {

std::string TestDataPath(const std::string& relative) {
  return std::string(GYRODRIFT_TESTDATA_DIR) + "/" + relative;
}

std::string TempDir(const std::string& name) {
  // CTest runs tests of one executable in parallel: the directory is unique per test.
  // Outside a test (SetUpTestSuite) every process runs the same suite set-up, so the process
  // id keeps concurrent processes apart.
  std::string unique = name;
  if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info()) {
    unique += std::string("-") + info->test_suite_name() + "-" + info->name();
    for (char& c : unique) {
      if (c == '/') c = '_';
    }
  } else {
    unique += "-pid" + std::to_string(::getpid());
  }
  const std::filesystem::path dir =
      std::filesystem::path(GYRODRIFT_BINARY_DIR) / "test-tmp" / unique;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

Eigen::MatrixXd ReadCsvMatrix(const std::string& path, std::vector<std::string>* header) {
  const auto table = io::CsvTable::Read(path);
  Eigen::MatrixXd m(table.rows(), static_cast<Eigen::Index>(table.header().size()));
  for (int c = 0; c < static_cast<int>(table.header().size()); ++c) m.col(c) = table.Column(c);
  if (header) *header = table.header();
  return m;
}

Eigen::VectorXd ReadF64(const std::string& path) {
  const std::string bytes = io::ReadTextFile(path);
  Eigen::VectorXd v(static_cast<Eigen::Index>(bytes.size() / sizeof(double)));
  std::memcpy(v.data(), bytes.data(), static_cast<size_t>(v.size()) * sizeof(double));
  return v;
}

double LehmerUniform::Next() {
  state_ = (16807 * state_) % 2147483647;
  return static_cast<double>(state_) / 2147483647.0;
}

Eigen::VectorXd LehmerBoxMullerNormals(std::int64_t seed, Eigen::Index n) {
  LehmerUniform uniform(seed);
  Eigen::VectorXd z(n);
  for (Eigen::Index j = 0; 2 * j < n; ++j) {
    const double u1 = uniform.Next();
    const double u2 = uniform.Next();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    z[2 * j] = radius * std::cos(angle);
    if (2 * j + 1 < n) z[2 * j + 1] = radius * std::sin(angle);
  }
  return z;
}

CommandResult RunCli(const std::string& args) {
  return RunShell(std::string("'") + GYRODRIFT_CLI + "' " + args);
}

CommandResult RunShell(const std::string& command_line) {
  CommandResult result;
  const std::string dir = TempDir("cli-capture");
  const std::string out_path = dir + "/stdout";
  const std::string err_path = dir + "/stderr";
  const std::string command = command_line + " >'" + out_path + "' 2>'" + err_path + "' </dev/null";
  const int status = std::system(command.c_str());
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = io::ReadTextFile(out_path);
  result.err = io::ReadTextFile(err_path);
  std::filesystem::remove_all(dir);
  return result;
}

bool FileExists(const std::string& path) { return std::filesystem::exists(path); }

std::string Substitute(std::string text,
                       const std::vector<std::pair<std::string, std::string>>& placeholders) {
  for (const auto& [key, value] : placeholders) {
    for (size_t p = 0; (p = text.find(key, p)) != std::string::npos; p += value.size()) {
      text.replace(p, key.size(), value);
    }
  }
  return text;
}

void ExpectCleanFailure(const CommandResult& result, int exit_code, const std::string& message,
                        const std::string& output, const std::string& label) {
  EXPECT_EQ(result.exit_code, exit_code) << label << ": " << result.err;
  EXPECT_EQ(result.err.rfind("gyrodrift: error: ", 0), 0u) << label << ": " << result.err;
  EXPECT_NE(result.err.find(message), std::string::npos) << label << ": " << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << label << ": " << result.err;
  EXPECT_FALSE(FileExists(output)) << label;
  EXPECT_FALSE(FileExists(output + ".json")) << label;
}

std::string ThermalLogCsv(int n, std::uint64_t seed, double step_s) {
  Rng rng(seed, 0);
  std::string csv = "time_s,rate_dph,temperature_c,drift_dph\n";
  double lagged = 20.0;
  for (int t = 0; t < n; ++t) {
    const double temperature = 20.0 + 15.0 * std::sin(2 * std::numbers::pi * 1.5 * t / n);
    const double previous = lagged;
    lagged += (temperature - lagged) / 40.0;
    const double drift = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous);
    csv += io::FormatDouble(t * step_s) + "," + io::FormatDouble(drift + 0.02 * rng.Normal()) +
           "," + io::FormatDouble(temperature) + "," + io::FormatDouble(drift) + "\n";
  }
  return csv;
}

html::DygraphsAssets FakeDygraphs() {
  return {"var Dygraph = function () {};" + std::string(60000, ' '), ".x{}"};
}

}  // namespace gyrodrift::test
