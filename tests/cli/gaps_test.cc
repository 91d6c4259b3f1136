// Logs with gaps (issue 22, item 4): every command that takes --gaps takes the same four modes and
// spells the flag as typed; carry fits on the logged rows only while the thermal states run
// across the gaps; interpolate marks the rows it made up and warns when most are; allan skips
// the cluster pairs that hold a made-up sample. Run as a user would, checked against the library.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/io/model_file.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class GapsCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_gaps"));
    // A 3000-s thermal log at 1 Hz and the duty-cycled logger's view of it: 10 s of every 60 s
    // (5/6 of the rows missing), and one log with a single 1000-s hole.
    const io::CsvTable full = io::CsvTable::Parse(test::ThermalLogCsv(3000, 7), "full");
    std::vector<io::CsvColumn> all, bursts, holed;
    for (const std::string& name : full.header()) all.push_back({name, full.Column(name)});
    for (const io::CsvColumn& c : all) {
      bursts.push_back({c.name, Eigen::VectorXd(500)});
      holed.push_back({c.name, Eigen::VectorXd(2000)});
      for (Eigen::Index b = 0; b < 50; ++b) bursts.back().values.segment(10 * b, 10) = c.values.segment(60 * b, 10);
      holed.back().values << c.values.head(1000), c.values.tail(1000);
    }
    io::WriteCsv(Dir() + "/full.csv", all);
    io::WriteCsv(Dir() + "/bursts.csv", bursts);
    io::WriteCsv(Dir() + "/holed.csv", holed);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }
  static std::string Path(const std::string& name) { return "'" + Dir() + "/" + name + "'"; }
  static std::string* dir_;
};
std::string* GapsCli::dir_ = nullptr;

TEST_F(GapsCli, CarryFitsOnTheLoggedRowsAndCompensateLeavesTheMadeUpRowsOut) {
  const std::string fit = "fit " + Path("bursts.csv") + " -t rate_dph -T temperature_c " +
                          "--mode compensate -m poly ";
  auto r = test::RunCli(fit + "--gaps carry -o " + Path("carry.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("2450 of 2950 rows (83.1 %) filled by linear interpolation"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("the 500 logged rows only (--gaps carry)"), std::string::npos) << r.out;
  // The library's fit of the filled log with its mask, to the bit.
  std::vector<bool> logged;
  const io::CsvTable filled =
      io::ReadLog(Dir() + "/bursts.csv", {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
  ASSERT_EQ(filled.rows(), 2950);
  const io::LoadedModel carry = io::ReadModelFile(Dir() + "/carry.json");
  const drift::DriftModel lib =
      drift::FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"),
                           carry.model.options, {}, {}, logged);
  EXPECT_EQ(lib.Summary(), carry.model.Summary());
  EXPECT_EQ(drift::EstimateDrift(lib, filled.Column("temperature_c")),
            drift::EstimateDrift(carry.model, filled.Column("temperature_c")));
  // Interpolate fits on the made-up rows too, and says that most of them are.
  r = test::RunCli(fit + "--gaps interpolate -o " + Path("interp.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("warning: time_s has 49 gaps (median step 1 s): 2450 of 2950 rows (83.1 %) "
                       "are made up by linear interpolation (--gaps interpolate)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("--gaps carry fits, scores and reports on the 500 logged rows only"),
            std::string::npos)
      << r.out;
  // ... and fits on them: the library's fit of the filled log without a mask.
  const io::LoadedModel interp = io::ReadModelFile(Dir() + "/interp.json");
  const drift::DriftModel unmasked = drift::FitDriftModel(
      filled.Column("rate_dph"), filled.Column("temperature_c"), interp.model.options);
  EXPECT_EQ(drift::EstimateDrift(interp.model, filled.Column("temperature_c")),
            drift::EstimateDrift(unmasked, filled.Column("temperature_c")));
  EXPECT_NE(drift::EstimateDrift(interp.model, filled.Column("temperature_c")),
            drift::EstimateDrift(carry.model, filled.Column("temperature_c")));
  // A decomposition would run across the made-up rows: refused, naming the method.
  r = test::RunCli("fit " + Path("bursts.csv") + " -t rate_dph -T temperature_c --mode compensate " +
                   "-m ms-elm --gaps carry -o " + Path("ms.json"));
  test::ExpectCleanFailure(r, 2,
                           "--gaps carry: the fit uses the logged rows only, which --mode "
                           "compensate --method ms-elm cannot do",
                           Dir() + "/ms.json", "ms-elm with carry");

  // compensate --gaps carry: one output row per logged row, the statistics over them.
  r = test::RunCli("compensate " + Path("carry.json") + " " + Path("bursts.csv") +
                   " --gaps carry --truth drift_dph -o " + Path("c_carry.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("rate_dph: statistics over the 500 logged rows (2450 made up left out)"), std::string::npos)
      << r.out;
  const io::CsvTable out_carry = io::CsvTable::Read(Dir() + "/c_carry.csv");
  EXPECT_EQ(out_carry.rows(), 500);
  EXPECT_EQ(out_carry.Column("time_s"), io::CsvTable::Read(Dir() + "/bursts.csv").Column("time_s"));
  EXPECT_FALSE(out_carry.HasColumn("interpolated"));
  const Eigen::VectorXd estimate = drift::EstimateDrift(carry.model, filled.Column("temperature_c"));
  EXPECT_EQ(out_carry.Column("drift_est"), Eigen::VectorXd(drift::LoggedRows(estimate, logged)));
  auto sidecar = nlohmann::json::parse(io::ReadTextFile(Dir() + "/c_carry.csv.json"));
  EXPECT_EQ(sidecar["rows"]["logged"], 500);
  EXPECT_EQ(sidecar["rows"]["made_up"], 2450);
  EXPECT_EQ(sidecar["rows"]["written"], 500);
  const Eigen::VectorXd y = out_carry.Column("rate_dph");
  EXPECT_NEAR(sidecar["std_before"].get<double>(),
              std::sqrt((y.array() - y.mean()).square().mean()), 1e-9);

  // compensate --gaps interpolate: every row, the made-up ones marked; statistics as carry's.
  r = test::RunCli("compensate " + Path("carry.json") + " " + Path("bursts.csv") +
                   " --gaps interpolate -q -o " + Path("c_interp.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvTable out_interp = io::CsvTable::Read(Dir() + "/c_interp.csv");
  ASSERT_EQ(out_interp.rows(), 2950);
  const Eigen::VectorXd flag = out_interp.Column("interpolated");
  for (Eigen::Index k = 0; k < flag.size(); ++k) {
    ASSERT_EQ(flag[k], logged[static_cast<size_t>(k)] ? 0.0 : 1.0) << "row " << k;
  }
  EXPECT_EQ(out_interp.Column("drift_est"), estimate);
  const auto interp_sidecar =
      nlohmann::json::parse(io::ReadTextFile(Dir() + "/c_interp.csv.json"));
  EXPECT_EQ(interp_sidecar["std_before"], sidecar["std_before"]);
  EXPECT_EQ(interp_sidecar["rows"]["written"], 2950);
}

TEST_F(GapsCli, EveryCommandTakesTheFourModesAndSpellsTheFlagAsTyped) {
  // The error names the three ways out as flags.
  auto r = test::RunCli("fit " + Path("holed.csv") + " -t rate_dph -T temperature_c " +
                        "--mode compensate -o " + Path("e.json"));
  test::ExpectCleanFailure(r, 3,
                           "(--gaps interpolate, or --gaps carry to fit on the logged rows only) "
                           "or split the log into records at its gaps (--gaps split)",
                           Dir() + "/e.json", "a gap refused");
  // A command that takes neither records nor logged rows offers interpolation alone.
  r = test::RunCli("decompose " + Path("holed.csv") + " -c rate_dph -o " + Path("d.csv"));
  test::ExpectCleanFailure(r, 3, "): fill gaps by linear interpolation (--gaps interpolate)\n",
                           Dir() + "/d.csv", "a gap refused by decompose");
  // Commands that analyse one uniform record refuse split and carry in one line, naming
  // themselves and the way out.
  for (const char* mode : {"split", "carry"}) {
    const std::string gaps = std::string(" --gaps ") + mode;
    for (const auto& [command, who] :
         std::vector<std::pair<std::string, std::string>>{
             {"decompose " + Path("holed.csv") + " -c rate_dph -o " + Path("d.csv"), "decompose"},
             {"evaluate " + Path("holed.csv") + " -t rate_dph -T temperature_c --mode compensate -o " + Path("d.csv"),
              "evaluate"}}) {
      r = test::RunCli(command + gaps);
      test::ExpectCleanFailure(r, 2, "--gaps " + std::string(mode) + ": " + who +
                                         " needs one uniform record",
                               Dir() + "/d.csv", who + gaps);
    }
  }
  // A mode that is not one of the four is refused by the flag's check.
  r = test::RunCli("allan " + Path("holed.csv") + " -c rate_dph --rate-hz 1 --gaps drop -o " +
                   Path("x.csv"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--gaps"), std::string::npos) << r.err;
}

// Predict mode on interpolated rows: the predictions there, and the first after each gap, read
// the sample after the gap; evaluate and predict say so, compensate mode has nothing to say.
TEST_F(GapsCli, PredictionsOfMadeUpRowsAreNotedAsNotCausal) {
  const std::string note = "rows --gaps interpolate made up (";
  const std::string evaluate = "evaluate " + Path("holed.csv") +
                               " -t rate_dph --gaps interpolate -o " + Path("ev.csv") + " --mode ";
  auto r = test::RunCli(evaluate + "predict --methods persistence");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(note), std::string::npos) << r.out;
  r = test::RunCli(evaluate + "compensate --methods poly -T temperature_c");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find(note), std::string::npos) << r.out;
}

TEST_F(GapsCli, AllanRefusesAColumnConstantWhereLoggedWhateverTheGaps) {
  // The break between joined records (split) or a made-up row (carry) is no variation: a stuck
  // sensor's log with a hole is refused as the same log without it is.
  std::string text = "time_s,rate_dph\n";
  for (int t = 0; t < 2000; ++t) {
    if (t < 1000 || t >= 1500) text += std::to_string(t) + ",2.5\n";
  }
  io::WriteFileAtomically(Dir() + "/stuck.csv", text);
  for (const char* gaps : {"split", "carry", "interpolate"}) {
    const auto r = test::RunCli("allan " + Path("stuck.csv") + " -c rate_dph --gaps " + gaps +
                                " -o " + Path("stuck_adev.csv"));
    test::ExpectCleanFailure(r, 3, "column 'rate_dph' is constant (every sample is 2.5)",
                             Dir() + "/stuck_adev.csv", std::string("stuck, --gaps ") + gaps);
  }
}

TEST_F(GapsCli, AllanSkipsTheClusterPairsThatHoldAMadeUpSample) {
  const std::string allan = "allan " + Path("holed.csv") + " -c rate_dph --rate-hz 1 ";
  // split (records joined with a break) and carry (the hole filled and masked) are the same
  // analysis: pairs inside the two 1000-sample runs.
  auto r = test::RunCli(allan + "--gaps split -q -o " + Path("a_split.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli(allan + "--gaps carry -o " + Path("a_carry.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvTable split = io::CsvTable::Read(Dir() + "/a_split.csv");
  const io::CsvTable carry = io::CsvTable::Read(Dir() + "/a_carry.csv");
  ASSERT_EQ(split.rows(), carry.rows());
  for (Eigen::Index k = 0; k < split.rows(); ++k) {
    EXPECT_EQ(split.Column("n_terms")[k], carry.Column("n_terms")[k]);
    EXPECT_NEAR(split.Column("dev")[k], carry.Column("dev")[k], 1e-9 * carry.Column("dev")[k]);
  }
  // m = 1: 999 pairs in each run.
  EXPECT_EQ(carry.Column("n_terms")[0], 2.0 * 999.0);
  // The library on the two runs with the hole masked.
  std::vector<bool> logged;
  const io::CsvTable filled =
      io::ReadLog(Dir() + "/holed.csv", {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
  const allan::AllanResult lib =
      allan::ComputeWithGaps(filled.Column("rate_dph"), logged, {.rate_hz = 1.0});
  ASSERT_EQ(static_cast<Eigen::Index>(lib.points.size()), carry.rows());
  EXPECT_DOUBLE_EQ(lib.points[3].dev, carry.Column("dev")[3]);
  const auto sidecar = nlohmann::json::parse(io::ReadTextFile(Dir() + "/a_carry.csv.json"));
  EXPECT_EQ(sidecar["logged_samples"], 2000);
  EXPECT_EQ(sidecar["options"]["gaps"], "carry");
  // An estimator that cannot skip pairs is refused with the flag that chose it.
  r = test::RunCli(allan + "--gaps carry --dev mdev -o " + Path("a_mdev.csv"));
  test::ExpectCleanFailure(r, 2, "--dev = mdev: must be oadev or ohdev for a record with gaps",
                           Dir() + "/a_mdev.csv", "mdev with carry");
  // interpolate analyses the made-up samples as data, and says so.
  r = test::RunCli(allan + "--gaps interpolate -o " + Path("a_interp.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("1000 samples filled by linear interpolation (--gaps interpolate)"),
            std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace gyrodrift
