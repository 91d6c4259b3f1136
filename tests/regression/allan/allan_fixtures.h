// Readers for the external Allan-variance reference data (../shared/testdata), shared by the
// regression tests of this folder.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/test_support.h"

namespace gyrodrift::allan::fixtures {

// One number per line; '#' lines and blank lines skipped.
inline Eigen::VectorXd ReadColumnFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<double> v;
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    v.push_back(std::strtod(line.c_str() + first, nullptr));
  }
  return Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// A row of a 7-column Stable32 table.
struct Stable32Row {
  std::int64_t af = 0;
  double tau = 0.0;
  std::int64_t n = 0;
  int alpha = 0;
  double min_sigma = 0.0, sigma = 0.0, max_sigma = 0.0;
};

inline std::vector<Stable32Row> ReadStable32(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<Stable32Row> rows;
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream s(line);
    Stable32Row r;
    if (s >> r.af >> r.tau >> r.n >> r.alpha >> r.min_sigma >> r.sigma >> r.max_sigma)
      rows.push_back(r);
  }
  return rows;
}

// Decompresses a .gz test file with the system gzip into the test's temp dir and returns the
// path of the plain copy.
inline std::string Gunzip(const std::string& gz_path, const std::string& name) {
  const std::string out = test::TempDir(name) + "/data.txt";
  const std::string cmd = "gzip -dc '" + gz_path + "' > '" + out + "'";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("gzip failed: " + cmd);
  return out;
}

inline double RelErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

}  // namespace gyrodrift::allan::fixtures
