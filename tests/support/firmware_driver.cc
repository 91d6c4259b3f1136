#include "support/firmware_driver.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <sstream>
#include <vector>

#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::test {
namespace {

// Steps the header HEADER (prefix PFX, macros PFXU) through a file of temperatures, one sample a
// line, and prints every axis' estimate with 17 digits.
constexpr const char* kHeaderDriver = R"(#include <stdio.h>
#include "HEADER"

static int read_sample(FILE *in, PFX_real t[PFXU_N_CHANNELS]) {
  double v;
  int c;
  for (c = 0; c < PFXU_N_CHANNELS; ++c) {
    if (fscanf(in, "%lf", &v) != 1) return 0;
    t[c] = (PFX_real)v;
  }
  return 1;
}

int main(int argc, char **argv) {
  PFX_state s;
  PFX_real t[PFXU_N_CHANNELS];
  PFX_real drift[PFXU_N_AXES];
  FILE *in;
  int a;
  if (argc != 2 || (in = fopen(argv[1], "r")) == NULL) return 2;
  if (!read_sample(in, t)) return 3;
  PFX_init(&s, t);
  do {
    PFX_step(&s, t, drift);
    for (a = 0; a < PFXU_N_AXES; ++a) printf(a ? " %.17g" : "%.17g", (double)drift[a]);
    printf("\n");
  } while (read_sample(in, t));
  fclose(in);
  return 0;
}
)";

std::string Quote(const std::string& s) { return "'" + s + "'"; }

}  // namespace

Eigen::MatrixXd RunFirmwareHeader(const std::string& header, const std::string& prefix,
                                  const Eigen::MatrixXd& temperature_c, const std::string& dir,
                                  const std::string& compiler, const std::string& flags) {
  const std::string stem = dir + "/" + prefix;
  std::string upper;
  for (char ch : prefix) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  // PFXU before PFX: one is a prefix of the other.
  io::WriteFileAtomically(
      stem + "_driver.c",
      Substitute(kHeaderDriver, {{"HEADER", header}, {"PFXU", upper}, {"PFX", prefix}}));
  const CommandResult compiled =
      RunShell(Quote(compiler) + " " + flags + " " + Quote(stem + "_driver.c") + " -o " +
               Quote(stem + "_driver"));
  EXPECT_EQ(compiled.exit_code, 0) << compiler << " " << flags << ": " << compiled.err;
  std::string text;
  char number[40];
  for (Eigen::Index i = 0; i < temperature_c.rows(); ++i) {
    for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
      std::snprintf(number, sizeof number, "%s%.17g", c ? " " : "", temperature_c(i, c));
      text += number;
    }
    text += '\n';
  }
  io::WriteFileAtomically(stem + "_in.txt", text);
  const CommandResult run = RunShell(Quote(stem + "_driver") + " " + Quote(stem + "_in.txt"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  std::vector<double> values;
  size_t lines = 0;
  for (char ch : run.out) lines += ch == '\n';
  std::istringstream in(run.out);
  for (double v; in >> v;) values.push_back(v);
  if (compiled.exit_code != 0 || run.exit_code != 0 || lines == 0 || values.size() % lines != 0) {
    ADD_FAILURE() << "the header's driver printed " << values.size() << " values on " << lines
                  << " lines";
    return {};
  }
  const auto axes = static_cast<Eigen::Index>(values.size() / lines);
  return Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      values.data(), static_cast<Eigen::Index>(lines), axes);
}

}  // namespace gyrodrift::test
