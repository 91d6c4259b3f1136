// The user's log is sacred: no command writes over one of its inputs, however the output path
// spells it (the same name, "./", another relative path, a symbolic link, a hard link), and the
// refusal comes before any work, with exit code 2 and a message naming both paths. The input is
// byte-identical afterwards.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <utility>
#include <string>
#include <vector>

#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class DataSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::TempDir("cli_data_safety");
    log_ = dir_ + "/log.csv";
    content_ = test::ThermalLogCsv(600, 3);
    io::WriteFileAtomically(log_, content_);
    std::filesystem::create_symlink(log_, dir_ + "/link.csv");
    std::filesystem::create_hard_link(log_, dir_ + "/hard.csv");
    ASSERT_EQ(test::RunCli("fit '" + log_ + "' -t rate_dph -T temperature_c --mode compensate -q " +
                           "-o '" + dir_ + "/model.json'")
                  .exit_code,
              0);
  }
  std::string dir_, log_, content_;
};

TEST_F(DataSafety, NoCommandOverwritesAnInputHoweverItIsSpelled) {
  const std::string d = dir_;
  const std::vector<std::string> spellings = {
      d + "/log.csv", d + "/./log.csv", d + "/../" + std::filesystem::path(d).filename().string() + "/log.csv",
      d + "/link.csv", d + "/hard.csv"};
  const std::vector<std::string> commands = {
      "decompose '%IN%' -c rate_dph --method emd -o '%OUT%'",
      "allan '%IN%' -c rate_dph --rate-hz 1 -o '%OUT%'",
      "fit '%IN%' -t rate_dph -T temperature_c --mode compensate -o '%OUT%'",
      "evaluate '%IN%' -t rate_dph -T temperature_c --mode compensate --methods poly -o '%OUT%'",
      "compensate '" + d + "/model.json' '%IN%' -o '%OUT%'",
  };
  for (const std::string& command : commands) {
    for (const std::string& out : spellings) {
      const std::string args = test::Substitute(command, {{"%IN%", log_}, {"%OUT%", out}});
      const test::CommandResult r = test::RunCli(args);
      EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
      EXPECT_NE(r.err.find("never overwrites its input"), std::string::npos) << args << r.err;
      EXPECT_EQ(io::ReadTextFile(log_), content_) << args;
    }
  }
  // A sidecar that would land on an input: OUT.csv.json is the model file.
  const test::CommandResult r =
      test::RunCli("compensate '" + d + "/model.json' '" + log_ + "' -o '" + d + "/model'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // The model file of compensate is an input too.
  EXPECT_EQ(test::RunCli("compensate '" + d + "/model.json' '" + log_ + "' -o '" + d +
                         "/model.json'")
                .exit_code,
            2);
  // demo refuses an output folder that holds its input.
  EXPECT_EQ(test::RunCli("demo --input '" + log_ + "' --target rate_dph -o '" + d + "'").exit_code,
            2);
  EXPECT_EQ(io::ReadTextFile(log_), content_);
  // A new path is fine.
  EXPECT_EQ(test::RunCli("decompose '" + log_ + "' -c rate_dph --method emd -q -o '" + d +
                         "/imfs.csv'")
                .exit_code,
            0);
}

TEST_F(DataSafety, TimeThatRepeatsOrGoesBackwardsIsRefusedWithItsRow) {
  // Rows 0..599 at 1 s; data row 301 repeats its predecessor, then row 301 goes back 5 s.
  for (const auto& [shift, word] : {std::pair{-1.0, "repeats"}, std::pair{-6.0, "goes backwards"}}) {
    std::string csv = "time_s,rate_dph,temperature_c\n";
    for (int i = 0; i < 600; ++i) {
      const double t = i < 300 ? i : i + shift;
      csv += std::to_string(t) + "," + std::to_string(0.01 * (i % 13)) + "," +
             std::to_string(20.0 + 10.0 * std::sin(i / 50.0)) + "\n";
    }
    const std::string path = dir_ + "/clock.csv";
    io::WriteFileAtomically(path, csv);
    for (const std::string& args :
         {"fit '" + path + "' -t rate_dph -T temperature_c --mode compensate -o '" + dir_ + "/m2.json'",
          "decompose '" + path + "' -c rate_dph --method emd -o '" + dir_ + "/i2.csv'",
          "allan '" + path + "' -c rate_dph --rate-hz 1 -o '" + dir_ + "/a2.csv'",
          "compensate '" + dir_ + "/model.json' '" + path + "' -o '" + dir_ + "/c2.csv'"}) {
      const test::CommandResult r = test::RunCli(args);
      EXPECT_EQ(r.exit_code, 3) << args << "\n" << r.err;
      EXPECT_NE(r.err.find(std::string("time_s ") + word + " at data row 301"), std::string::npos)
          << args << "\n" << r.err;
    }
  }
}

}  // namespace
}  // namespace gyrodrift
