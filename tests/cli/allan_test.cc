// gyrodrift allan: the main path and every bad-input case, on the real binary.
#include "gyrodrift/allan/allan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "gyrodrift/common/random.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

// A 1 Hz gyro log: white rate noise (N = 0.3 / 60 deg/sqrt(h)) plus a random-walk bias.
std::string WriteLog(const std::string& dir, Eigen::Index n = 20000) {
  Rng white(5, StreamId("arw")), walk(5, StreamId("rrw"));
  Eigen::VectorXd rate(n), time(n);
  double bias = 1.5;
  for (Eigen::Index i = 0; i < n; ++i) {
    bias += 0.002 * walk.Normal();
    rate[i] = 0.3 * white.Normal() + bias;
    time[i] = static_cast<double>(i);
  }
  const std::string path = dir + "/fog.csv";
  io::WriteCsv(path, {{"time_s", time}, {"rate_dph", rate}});
  return path;
}

std::string Q(const std::string& s) { return "'" + s + "'"; }

TEST(CliAllan, WritesCsvSidecarAndNoiseTable) {
  const std::string dir = test::TempDir("cli-allan-main");
  const std::string log = WriteLog(dir);
  const std::string out = dir + "/adev.csv";
  const auto r = test::RunCli("allan " + Q(log) + " --column rate_dph --rate-hz 1 -o " + Q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("N angle random walk [deg/sqrt(h)]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("slope method"), std::string::npos);
  std::vector<std::string> header;
  const Eigen::MatrixXd csv = test::ReadCsvMatrix(out, &header);
  EXPECT_EQ(header, (std::vector<std::string>{"tau_s", "dev", "dev_lo", "dev_hi", "n_terms"}));
  ASSERT_EQ(csv.rows(), 14);  // octave taus 1..8192 s of 20001 angle points
  // The CSV carries the library's numbers at full precision.
  const io::CsvTable table = io::CsvTable::Read(log);
  allan::AllanOptions o{.rate_hz = 1.0};
  const allan::AllanResult lib = allan::Compute(table.Column("rate_dph"), o);
  for (Eigen::Index i = 0; i < csv.rows(); ++i) {
    EXPECT_EQ(csv(i, 0), lib.points[static_cast<size_t>(i)].tau_s);
    EXPECT_EQ(csv(i, 1), lib.points[static_cast<size_t>(i)].dev);
    EXPECT_EQ(csv(i, 2), lib.points[static_cast<size_t>(i)].dev_lo);
    EXPECT_EQ(csv(i, 4), static_cast<double>(lib.points[static_cast<size_t>(i)].n_terms));
    EXPECT_LT(csv(i, 2), csv(i, 1));
    EXPECT_GT(csv(i, 3), csv(i, 1));
  }
  const auto j = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(j["command"], "allan");
  EXPECT_EQ(j["options"]["dev"], "oadev");
  EXPECT_EQ(j["options"]["rate_hz"], 1.0);
  EXPECT_EQ(j["options"]["confidence"], 0.683);
  EXPECT_EQ(j["points"].size(), 14u);
  const double n_fit = j["noise_terms"]["N"]["value"].get<double>();
  EXPECT_NEAR(n_fit / (0.3 / 60.0), 1.0, 0.05);
  EXPECT_TRUE(j["noise_terms"]["K"]["identified"].get<bool>());
}

TEST(CliAllan, ListGridIndexColumnAndOtherEstimators) {
  const std::string dir = test::TempDir("cli-allan-list");
  const std::string log = WriteLog(dir, 3000);
  for (const char* dev : {"adev", "mdev", "hdev", "ohdev", "tdev", "totdev"}) {
    const std::string out = dir + "/" + dev + ".csv";
    const auto r = test::RunCli("allan " + Q(log) + " -c 2 --rate-hz 2 --units dps --dev " + dev +
                                " --taus 0.5,5,50 --confidence 0.95 -j 1 -o " + Q(out));
    ASSERT_EQ(r.exit_code, 0) << dev << ": " << r.err;
    const Eigen::MatrixXd csv = test::ReadCsvMatrix(out);
    ASSERT_EQ(csv.rows(), 3) << dev;
    EXPECT_EQ(csv(1, 0), 5.0);
  }
  // Every averaging factor.
  const auto r = test::RunCli("allan " + Q(log) + " -c rate_dph --rate-hz 1 --taus all -o " +
                              Q(dir + "/all.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::ReadCsvMatrix(dir + "/all.csv").rows(), 1500);
}

// Without --rate-hz the rate is 1 / the step of time_s: the same numbers as given, said.
TEST(CliAllan, RateFromTimeColumnWhenNotGiven) {
  const std::string dir = test::TempDir("cli-allan-rate");
  const Eigen::Index n = 4000;
  Rng white(9, StreamId("arw"));
  Eigen::VectorXd rate(n), time(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    rate[i] = 0.3 * white.Normal();
    time[i] = 1000.0 + 0.5 * static_cast<double>(i);  // 2 Hz
  }
  const std::string log = dir + "/imu.csv";
  io::WriteCsv(log, {{"time_s", time}, {"rate_dph", rate}});
  const auto read = test::RunCli("allan " + Q(log) + " -c rate_dph -o " + Q(dir + "/read.csv"));
  ASSERT_EQ(read.exit_code, 0) << read.err;
  EXPECT_NE(read.out.find("sample rate: 2 Hz (from the steps of time_s)"), std::string::npos)
      << read.out;
  const auto given =
      test::RunCli("allan " + Q(log) + " -c rate_dph --rate-hz 2 -o " + Q(dir + "/given.csv"));
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_EQ(given.out.find("sample rate:"), std::string::npos) << given.out;
  EXPECT_EQ(io::ReadTextFile(dir + "/read.csv"), io::ReadTextFile(dir + "/given.csv"));
  const auto j = nlohmann::json::parse(io::ReadTextFile(dir + "/read.csv.json"));
  EXPECT_EQ(j["options"]["rate_hz"], 2.0);
  EXPECT_EQ(j["options"]["rate_hz_from"], "time_s");
  const auto g = nlohmann::json::parse(io::ReadTextFile(dir + "/given.csv.json"));
  EXPECT_EQ(g["options"]["rate_hz_from"], "given");
}

TEST(CliAllan, HelpShowsAWorkedExample) {
  const auto r = test::RunCli("allan --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Example:"), std::string::npos);
  EXPECT_NE(r.out.find("gyrodrift allan fog.csv --column rate_dph --rate-hz 1"), std::string::npos);
}

struct BadCase {
  std::string name;
  std::string args;  // after "allan"; $LOG, $BAD, $NAN, $SHORT, $OUT substituted
  int exit_code;
  std::string message;  // part of the one-line error
};

TEST(CliAllan, BadInputGivesOneLineErrorAndNoOutput) {
  const std::string dir = test::TempDir("cli-allan-bad");
  const std::string log = WriteLog(dir, 200);
  {
    std::ofstream(dir + "/bad.csv") << "rate_dph\n1.0\nabc\n2.0\n";
    std::ofstream(dir + "/nan.csv") << "rate_dph\n1.0\nnan\n2.0\n";
    std::ofstream(dir + "/inf.csv") << "rate_dph\n1.0\ninf\n2.0\n";
    std::ofstream(dir + "/short.csv") << "rate_dph\n1.0\n";
    std::ofstream(dir + "/constant.csv") << "rate_dph\n3\n3\n3\n3\n";
    std::ofstream(dir + "/untimed.csv") << "rate_dph\n1\n2\n3\n1\n2\n";
  }
  const BadCase cases[] = {
      {"no file", "$DIR/missing.csv -c rate_dph --rate-hz 1 -o $OUT", 2, "no such file"},
      {"no column", "$LOG -c gyro_z --rate-hz 1 -o $OUT", 2, "gyro_z"},
      {"column index out of range", "$LOG -c 9 --rate-hz 1 -o $OUT", 2, "9"},
      {"non-numeric cell", "$DIR/bad.csv -c rate_dph --rate-hz 1 -o $OUT", 3, "abc"},
      {"NaN", "$DIR/nan.csv -c rate_dph --rate-hz 1 -o $OUT", 3, "row"},
      {"Inf", "$DIR/inf.csv -c rate_dph --rate-hz 1 -o $OUT", 3, "row"},
      {"too few samples", "$DIR/short.csv -c rate_dph --rate-hz 1 -o $OUT", 3, "sample"},
      {"tau beyond record", "$LOG -c rate_dph --rate-hz 1 --taus 1,150 -o $OUT", 3, "tau 150"},
      {"rate zero", "$LOG -c rate_dph --rate-hz 0 -o $OUT", 2, "--rate-hz = 0"},
      {"rate negative", "$LOG -c rate_dph --rate-hz -5 -o $OUT", 2, "--rate-hz"},
      {"rate missing, no time_s", "$DIR/untimed.csv -c rate_dph -o $OUT", 2,
       "--rate-hz is required: " + dir + "/untimed.csv has no time_s column"},
      {"non-positive tau", "$LOG -c rate_dph --rate-hz 1 --taus 1,0,10 -o $OUT", 2, "--taus"},
      {"negative tau", "$LOG -c rate_dph --rate-hz 1 --taus -3 -o $OUT", 2, "--taus"},
      {"junk tau", "$LOG -c rate_dph --rate-hz 1 --taus 1,x -o $OUT", 2, "--taus"},
      {"tau between samples", "$LOG -c rate_dph --rate-hz 1 --taus 1,1.5 -o $OUT", 2,
       "--taus = 1.5: must be a whole number of sample periods at 1 Hz (nearest: 2 s)"},
      {"tau below one sample", "$LOG -c rate_dph --rate-hz 2 --taus 0.2 -o $OUT", 2,
       "nearest: 0.5 s"},
      {"absurd rate", "$LOG -c rate_dph --rate-hz 1e308 -o $OUT", 2, "--rate-hz = 1e+308"},
      {"constant column", "$DIR/constant.csv -c rate_dph --rate-hz 1 -o $OUT", 3,
       "column 'rate_dph' is constant"},
      {"bad dev", "$LOG -c rate_dph --rate-hz 1 --dev allan -o $OUT", 2, "--dev = 'allan'"},
      {"bad type", "$LOG -c rate_dph --rate-hz 1 --type phase -o $OUT", 2, "--type = 'phase'"},
      {"bad units", "$LOG -c rate_dph --rate-hz 1 --units rpm -o $OUT", 2, "--units = 'rpm'"},
      {"bad confidence", "$LOG -c rate_dph --rate-hz 1 --confidence 1.5 -o $OUT", 2,
       "--confidence = 1.5"},
      {"bad threads", "$LOG -c rate_dph --rate-hz 1 --threads -2 -o $OUT", 2, "--threads = -2"},
      {"bad fit range", "$LOG -c rate_dph --rate-hz 1 --fit-tau-min 10 --fit-tau-max 5 -o $OUT", 2,
       "--fit-tau-max = 5: must be > the smallest fitted tau (10)"},
      {"missing output", "$LOG -c rate_dph --rate-hz 1", 2, "output"},
  };
  const std::string out = dir + "/out.csv";
  for (const auto& c : cases) {
    const auto r = test::RunCli(
        "allan " + test::Substitute(c.args, {{"$LOG", Q(log)}, {"$DIR", dir}, {"$OUT", Q(out)}}));
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
}

}  // namespace
}  // namespace gyrodrift
