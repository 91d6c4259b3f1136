// Calibration data in several pieces (issue 13): several calibration logs fitted as one run of
// records, a log split at its gaps (--gaps split) giving the same model, compensation restarting
// after each gap, and --delimiter. Run as a user would, checked against the library to the bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class RecordsCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_records"));
    // Two chamber runs of the same gyro (new noise), and the same two as one log whose time_s
    // jumps by 1000 s where the logger stopped between them.
    const io::CsvTable a = io::CsvTable::Parse(test::ThermalLogCsv(3000, 5), "a");
    const io::CsvTable b = io::CsvTable::Parse(test::ThermalLogCsv(2000, 6), "b");
    io::WriteCsv(Dir() + "/a.csv", Columns(a, 0.0));
    io::WriteCsv(Dir() + "/b.csv", Columns(b, 0.0));
    std::vector<io::CsvColumn> joined = Columns(a, 0.0);
    const std::vector<io::CsvColumn> later = Columns(b, 4000.0);
    for (size_t c = 0; c < joined.size(); ++c) {
      const Eigen::Index n = joined[c].values.size();
      joined[c].values.conservativeResize(n + later[c].values.size());
      joined[c].values.tail(later[c].values.size()) = later[c].values;
    }
    io::WriteCsv(Dir() + "/gap.csv", joined);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static std::vector<io::CsvColumn> Columns(const io::CsvTable& t, double offset_s) {
    std::vector<io::CsvColumn> out;
    for (const std::string& name : t.header()) out.push_back({name, t.Column(name)});
    out[0].values.array() += offset_s;
    return out;
  }
  static const std::string& Dir() { return *dir_; }
  static std::string* dir_;
  static std::string Path(const std::string& name) { return "'" + Dir() + "/" + name + "'"; }
};
std::string* RecordsCli::dir_ = nullptr;

TEST_F(RecordsCli, SeveralCalibrationLogsAreFittedAsRecordsOfOneRun) {
  const std::string fit = "fit " + Path("a.csv") + " " + Path("b.csv") +
                          " -t rate_dph -T temperature_c --mode compensate ";
  auto r = test::RunCli(fit + "-o " + Path("two.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("in 2 records"), std::string::npos) << r.out;
  const io::LoadedModel two = io::ReadModelFile(Dir() + "/two.json");
  EXPECT_EQ(two.info.source, Dir() + "/a.csv," + Dir() + "/b.csv");
  ASSERT_TRUE(two.model.sub_models.front().thermal);
  EXPECT_EQ(two.model.sub_models.front().thermal->report.records, 2);

  // The library's fit of the two logs one after the other, the second a record of its own.
  const io::CsvTable a = io::CsvTable::Read(Dir() + "/a.csv");
  const io::CsvTable b = io::CsvTable::Read(Dir() + "/b.csv");
  Eigen::VectorXd y(a.rows() + b.rows()), t(a.rows() + b.rows());
  y << a.Column("rate_dph"), b.Column("rate_dph");
  t << a.Column("temperature_c"), b.Column("temperature_c");
  drift::DriftOptions o = two.model.options;
  const drift::DriftModel lib = drift::FitDriftModel(y, t, o, {a.rows()});
  EXPECT_EQ(lib.sub_models.front().thermal->coefficients,
            two.model.sub_models.front().thermal->coefficients);

  // Methods whose decomposition or lags would run across the break refuse, before any fit.
  r = test::RunCli(fit + "-m ms-elm -o " + Path("ms.json"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("several records (several input logs) are fitted by --method thermal"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(test::FileExists(Dir() + "/ms.json"));
  // Logs of different sample rates cannot be one run.
  io::CsvTable fast = io::CsvTable::Read(Dir() + "/b.csv");
  std::vector<io::CsvColumn> columns = Columns(fast, 0.0);
  columns[0].values *= 0.1;
  io::WriteCsv(Dir() + "/fast.csv", columns);
  r = test::RunCli("fit " + Path("a.csv") + " " + Path("fast.csv") +
                   " -t rate_dph -T temperature_c --mode compensate -o " + Path("f.json"));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("fast.csv at 10 Hz: calibration logs fitted together need one sample rate"),
            std::string::npos)
      << r.err;
  // A log fitted with itself would be an output that is an input: the output check names it.
  r = test::RunCli(fit + "-o " + Path("b.csv"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // evaluate holds out part of one log: it takes one.
  r = test::RunCli("evaluate " + Path("a.csv") + " " + Path("b.csv") +
                   " -t rate_dph -T temperature_c --mode compensate -o " + Path("e.csv"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
}

TEST_F(RecordsCli, ALogSplitAtItsGapIsTheTwoLogs) {
  const std::string fit = "fit " + Path("gap.csv") + " -t rate_dph -T temperature_c " +
                          "--mode compensate ";
  auto r = test::RunCli(fit + "-o " + Path("g.json"));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("time_s jumps by 1001 s before data row 3001"), std::string::npos) << r.err;
  r = test::RunCli(fit + "--gaps split -o " + Path("split.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("the log is split into 2 records"), std::string::npos) << r.out;
  ASSERT_EQ(test::RunCli("fit " + Path("a.csv") + " " + Path("b.csv") +
                         " -t rate_dph -T temperature_c --mode compensate -q -o " + Path("ab.json"))
                .exit_code,
            0);
  const io::LoadedModel split = io::ReadModelFile(Dir() + "/split.json");
  const io::LoadedModel ab = io::ReadModelFile(Dir() + "/ab.json");
  EXPECT_EQ(split.model.sub_models.front().thermal->coefficients,
            ab.model.sub_models.front().thermal->coefficients);

  // Compensation restarts the model's states after the gap: the estimate of the split log is
  // those of its two pieces, to the bit.
  r = test::RunCli("compensate " + Path("ab.json") + " " + Path("gap.csv") + " --gaps split -o " +
                   Path("gap_c.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* piece : {"a", "b"}) {
    ASSERT_EQ(test::RunCli("compensate " + Path("ab.json") + " " + Path(std::string(piece) + ".csv") +
                           " -q -o " + Path(std::string(piece) + "_c.csv"))
                  .exit_code,
              0);
  }
  const Eigen::VectorXd whole = io::CsvTable::Read(Dir() + "/gap_c.csv").Column("drift_est");
  const Eigen::VectorXd a = io::CsvTable::Read(Dir() + "/a_c.csv").Column("drift_est");
  const Eigen::VectorXd b = io::CsvTable::Read(Dir() + "/b_c.csv").Column("drift_est");
  ASSERT_EQ(whole.size(), a.size() + b.size());
  EXPECT_EQ(whole.head(a.size()), a);
  EXPECT_EQ(whole.tail(b.size()), b);
  const auto sidecar =
      nlohmann::json::parse(io::ReadTextFile(Dir() + "/gap_c.csv.json"));
  EXPECT_EQ(sidecar["options"]["records"], 2);

  // A decomposition needs one uniform record: it refuses split, naming itself (an Allan
  // analysis pools the records: tests/cli/gaps_test.cc).
  r = test::RunCli("decompose " + Path("gap.csv") + " -c rate_dph -o " + Path("d.csv") +
                   " --gaps split");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--gaps split: decompose needs one uniform record"), std::string::npos)
      << r.err;
}

TEST_F(RecordsCli, TheDelimiterCanBeNamed) {
  // A semicolon-separated export whose header names a column with a comma in it: detection takes
  // the comma, --delimiter semicolon reads it.
  const io::CsvTable a = io::CsvTable::Read(Dir() + "/a.csv");
  std::string text = "time_s;rate (deg/h, x);temperature_c\n";
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    text += io::FormatDouble(a.Column("time_s")[i]) + ";" +
            io::FormatDouble(a.Column("rate_dph")[i]) + ";" +
            io::FormatDouble(a.Column("temperature_c")[i]) + "\n";
  }
  io::WriteFileAtomically(Dir() + "/semi.csv", text);
  const std::string fit = "fit " + Path("semi.csv") + " -t 2 -T temperature_c " +
                          "--mode compensate -q ";
  auto r = test::RunCli(fit + "-o " + Path("semi.json"));
  EXPECT_EQ(r.exit_code, 3) << r.err;  // the comma splits the header into two cells: ragged rows
  r = test::RunCli(fit + "--delimiter semicolon -o " + Path("semi.json"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli(fit + "--delimiter pipe -o " + Path("pipe.json"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--delimiter"), std::string::npos) << r.err;
  // The same column as a temperature cannot be recorded (a model file separates its temperature
  // columns by commas): refused at the fit, not when the model is loaded.
  r = test::RunCli("fit " + Path("semi.csv") + " -t temperature_c -T 2 --mode compensate " +
                   "--delimiter semicolon -o " + Path("semi_t.json"));
  test::ExpectCleanFailure(r, 2,
                           "--temperature = 'rate (deg/h, x)': must be a column name without a "
                           "comma",
                           Dir() + "/semi_t.json", "a temperature named with a comma");
}

}  // namespace
}  // namespace gyrodrift
