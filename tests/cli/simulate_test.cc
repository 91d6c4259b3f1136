// gyrodrift simulate, run as a user would: the main path, determinism, profiles from files, and
// every bad-input case (one-line error, exit code, no partial output).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class SimulateCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::TempDir("cli_simulate"); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  // Runs the command and checks the failure contract: exit code, one line on stderr, no output.
  void ExpectFailure(const std::string& args, int exit_code, const std::string& fragment) {
    const std::string out = Path("fail.csv");
    const auto r = test::RunCli("simulate " + args + " -o '" + out + "'");
    EXPECT_EQ(r.exit_code, exit_code) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("gyrodrift: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(test::FileExists(out)) << args;
    EXPECT_FALSE(test::FileExists(out + ".json")) << args;
  }
  std::string dir_;
};

TEST_F(SimulateCli, WritesTheDocumentedColumnsAndSidecar) {
  const std::string out = Path("fog.csv");
  const auto r = test::RunCli("simulate --duration 1h --seed 7 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3600 samples"), std::string::npos) << r.out;
  const auto table = io::CsvTable::Read(out);
  const std::vector<std::string> header = {"time_s",    "rate_dph",   "temperature_c", "drift_dph",
                                           "shupe_dph", "stress_dph", "bias_dph",      "noise_dph"};
  EXPECT_EQ(table.header(), header);
  ASSERT_EQ(table.rows(), 3600);
  EXPECT_EQ(table.Column("time_s")[0], 1.0);
  EXPECT_EQ(table.Column("time_s")[3599], 3600.0);
  // The truth adds up through the text round trip.
  const Eigen::VectorXd drift = table.Column("drift_dph");
  EXPECT_LT(
      (drift - table.Column("shupe_dph") - table.Column("stress_dph") - table.Column("bias_dph"))
          .cwiseAbs()
          .maxCoeff(),
      1e-12);
  EXPECT_LT((table.Column("rate_dph") - drift - table.Column("noise_dph")).cwiseAbs().maxCoeff(),
            1e-12);
  // The chamber starts its ramp at 30 min: the case sensor warms by the end of the hour.
  EXPECT_GT(table.Column("temperature_c")[3599], table.Column("temperature_c")[0] + 5.0);
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["command"], "simulate");
  EXPECT_EQ(json["seed"], 7);
  EXPECT_EQ(json["options"]["seed"], 7);
  EXPECT_EQ(json["options"]["duration_s"], 3600.0);
  EXPECT_EQ(json["parameters"]["preset"], "navigation");
  EXPECT_EQ(json["parameters"]["coil"]["fibre_length_m"], 1000.0);
  EXPECT_EQ(json["parameters"]["coil"]["winding"], "quadrupole");
  EXPECT_EQ(json["parameters"]["noise"]["arw_dpsh"], 4.58e-3);
  EXPECT_EQ(json["programme"]["name"], "chamber");
  EXPECT_GT(json["report"]["coil_lag_s"].get<double>(), 300.0);
}

TEST_F(SimulateCli, SameSeedSameBytesOtherSeedOtherNoise) {
  const std::string a = Path("a.csv"), b = Path("b.csv"), c = Path("c.csv");
  const std::string args = "simulate --preset tactical --profile chamber-b --duration 2h -q ";
  ASSERT_EQ(test::RunCli(args + "--seed 5 -o '" + a + "'").exit_code, 0);
  ASSERT_EQ(test::RunCli(args + "--seed 5 -o '" + b + "'").exit_code, 0);
  ASSERT_EQ(test::RunCli(args + "--seed 6 -o '" + c + "'").exit_code, 0);
  EXPECT_EQ(io::ReadTextFile(a), io::ReadTextFile(b));
  EXPECT_EQ(io::ReadTextFile(a + ".json"), io::ReadTextFile(b + ".json"));
  EXPECT_NE(io::ReadTextFile(a), io::ReadTextFile(c));
  const auto ta = io::CsvTable::Read(a), tc = io::CsvTable::Read(c);
  EXPECT_EQ(ta.Column("drift_dph"),
            tc.Column("drift_dph"));  // the truth does not depend on the seed
  EXPECT_NE(ta.Column("noise_dph"), tc.Column("noise_dph"));
}

TEST_F(SimulateCli, DurationsRatesAndProfiles) {
  struct Case {
    std::string args;
    Eigen::Index rows;
  };
  const std::vector<Case> cases = {
      {"--duration 30s", 30},
      {"--duration 10min --rate-hz 0.5", 300},
      {"--duration 120", 120},
      {"--duration 0.5h --rate-hz 2", 3600},
      {"--profile sine --duration 2h --rate-hz 0.1", 720},
      {"--profile chamber-b --rate-hz 0.01", 288},  // default duration: the profile's 8 h
      {"--preset tactical --winding conventional --asymmetry 0 --no-noise --duration 1h", 3600},
  };
  for (const auto& c : cases) {
    const std::string out = Path("d.csv");
    const auto r = test::RunCli("simulate " + c.args + " -q -o '" + out + "'");
    ASSERT_EQ(r.exit_code, 0) << c.args << "\n" << r.err;
    EXPECT_EQ(io::CsvTable::Read(out).rows(), c.rows) << c.args;
  }
  const auto noise_free = io::CsvTable::Read(Path("d.csv"));
  EXPECT_EQ(noise_free.Column("noise_dph").cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(noise_free.Column("rate_dph"), noise_free.Column("drift_dph"));
}

TEST_F(SimulateCli, ProfileFromCsvFile) {
  const std::string profile = Path("profile.csv");
  io::WriteFileAtomically(profile, "time_s,temperature_c\n0,20\n600,20\n1800,40\n3600,40\n");
  const std::string out = Path("p.csv");
  const auto r = test::RunCli("simulate --profile '" + profile + "' --no-noise -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = io::CsvTable::Read(out);
  EXPECT_EQ(table.rows(), 3600);  // default duration: the file's last time
  // No heating before 600 s, so no Shupe term; heating afterwards makes one.
  EXPECT_EQ(table.Column("shupe_dph").head(600).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(table.Column("shupe_dph").tail(3000).cwiseAbs().maxCoeff(), 0.0);
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["programme"]["breakpoint_temperature_c"][2], 40.0);
}

TEST_F(SimulateCli, BadProfileFilesAreDataErrors) {
  const auto write = [&](const std::string& name, const std::string& text) {
    io::WriteFileAtomically(Path(name), text);
    return "--profile '" + Path(name) + "'";
  };
  ExpectFailure(write("nocol.csv", "time_s,temp\n0,20\n10,30\n"), 3, "temperature_c");
  ExpectFailure(write("notime.csv", "t,temperature_c\n0,20\n10,30\n"), 3, "time_s");
  ExpectFailure(write("nan.csv", "time_s,temperature_c\n0,20\n10,nan\n20,30\n"), 3,
                "temperature_c");
  ExpectFailure(write("text.csv", "time_s,temperature_c\n0,20\n10,warm\n"), 3, "temperature_c");
  ExpectFailure(write("back.csv", "time_s,temperature_c\n0,20\n10,30\n5,25\n"), 3, "increase");
  ExpectFailure(write("one.csv", "time_s,temperature_c\n0,20\n"), 3, "at least 2");
  ExpectFailure(write("kelvin.csv", "time_s,temperature_c\n0,293\n10,300\n"), 3, "[-100, 200]");
  ExpectFailure(write("empty.csv", "time_s,temperature_c\n"), 3, "");
}

TEST_F(SimulateCli, BadOptionsAreUsageErrors) {
  ExpectFailure("--profile oven", 2, "--profile = oven");
  ExpectFailure("--profile '" + Path("missing.csv") + "'", 2, "missing.csv");
  ExpectFailure("--preset strategic", 2, "preset = 'strategic'");
  ExpectFailure("--duration 8x", 2, "--duration = 8x");
  ExpectFailure("--duration -5s", 2, "--duration");
  ExpectFailure("--duration 0", 2, "--duration = 0");
  ExpectFailure("--duration 1s", 2, "--duration = 1");  // a single sample
  // The duration was not typed (the profile's 8 h): the message does not blame --duration.
  ExpectFailure("--rate-hz 1000", 2, ": error: duration_s = 28800 s: must be");
  ExpectFailure("--duration 1e400", 2, "--duration = 1e400");
  ExpectFailure("--duration 200d", 2, "--duration = 200d");
  ExpectFailure("--duration 3000h", 2, "1e7 samples");
  ExpectFailure("--rate-hz 0", 2, "--rate-hz = 0");
  ExpectFailure("--rate-hz abc", 2, "rate-hz");
  ExpectFailure("--winding sextupole", 2, "winding = 'sextupole'");
  ExpectFailure("--asymmetry 0.7", 2, "--asymmetry = 0.7");
  ExpectFailure("--asymmetry nan", 2, "--asymmetry = nan");
  ExpectFailure("--seed -1", 2, "--seed: -1: must be an integer");
  ExpectFailure("--seed 18446744073709551616", 2, "must be an integer in [0, 2^64)");
  ExpectFailure("--bogus", 2, "bogus");
  // -o missing altogether.
  const auto r = test::RunCli("simulate --duration 1h");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("output"), std::string::npos) << r.err;
}

TEST_F(SimulateCli, UnwritableOutputIsAnIoErrorWithNothingLeft) {
  const std::string out = Path("no/such/dir/out.csv");
  const auto r = test::RunCli("simulate --duration 60 -o '" + out + "'");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_FALSE(test::FileExists(out));
}

// A builtin profile's name is not a file, whatever lies in the folder under that name.
TEST_F(SimulateCli, AnOutputNamedAsAProfileIsNotTakenForTheInput) {
  for (int run = 0; run < 2; ++run) {
    // From the output's folder, where "chamber" is the file the first run wrote.
    const auto r = test::RunShell("cd '" + dir_ + "' && '" + GYRODRIFT_CLI +
                                  "' simulate --duration 60 --profile chamber -q -o chamber");
    EXPECT_EQ(r.exit_code, 0) << "run " << run << ": " << r.err;
  }
  EXPECT_TRUE(test::FileExists(Path("chamber")));
}

TEST_F(SimulateCli, HelpShowsAWorkedExample) {
  const auto r = test::RunCli("simulate --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Example:"), std::string::npos);
  EXPECT_NE(r.out.find("gyrodrift simulate --preset navigation --profile chamber"),
            std::string::npos);
  EXPECT_NE(r.out.find("time_s,rate_dph,temperature_c,drift_dph"), std::string::npos);
}

}  // namespace
}  // namespace gyrodrift
