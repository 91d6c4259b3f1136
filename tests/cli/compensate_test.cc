// gyrodrift compensate, run as a user would: the output columns, identity with the library, that
// compensation removes drift on a new log, and every bad-input case.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

double Rms(const Eigen::VectorXd& v) {
  return std::sqrt(v.squaredNorm() / static_cast<double>(v.size()));
}

class CompensateCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_compensate"));
    io::WriteFileAtomically(Dir() + "/train.csv", test::ThermalLogCsv(600, 1));
    // The same programme with new noise.
    io::WriteFileAtomically(Dir() + "/test.csv", test::ThermalLogCsv(600, 2));
    const std::string fit = "fit '" + Dir() + "/train.csv' -t rate_dph -T temperature_c -I 10 -q ";
    ASSERT_EQ(test::RunCli(fit + "--mode compensate -o '" + Dir() + "/ms.json'").exit_code, 0);
    ASSERT_EQ(test::RunCli(fit + "--mode predict -m elm -o '" + Dir() + "/pred.json'").exit_code,
              0);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }
  static std::string* dir_;
};
std::string* CompensateCli::dir_ = nullptr;

// --drift-window-s: the slow variation's blocks (the manifest's drift_window_s), as
// drift::SummariseCompensation computes it over blocks of that length; refused out of range.
TEST_F(CompensateCli, TheDriftWindowSetsTheSlowVariationsBlocks) {
  const std::string out = Dir() + "/window.csv";
  const auto r = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                              "/test.csv' --drift-window-s 60 -q -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json side = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(side["slow_variation_block_s"].get<double>(), 60.0);
  EXPECT_EQ(side["slow_variation_blocks"].get<int>(), 10);
  const io::CsvTable t = io::CsvTable::Read(out);
  const drift::CompensationSummary s =
      drift::SummariseCompensation(t.Column("rate_dph"), t.Column("compensated"), 1.0, 60.0);
  EXPECT_EQ(side["after"]["slow_variation"].get<double>(), s.after.slow);
  test::ExpectCleanFailure(test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                                        "/test.csv' --drift-window-s 0 -o '" + out + "2'"),
                           2, "--drift-window-s = 0: must be in [0.001, 1e+09]", out + "2",
                           "drift window 0");
}

TEST_F(CompensateCli, AddsTheEstimateAndTheCompensatedOutput) {
  const std::string out = Dir() + "/out.csv";
  const auto r =
      test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() + "/test.csv' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("thermal (compensate)"), std::string::npos) << r.out;
  const auto table = io::CsvTable::Read(out);
  EXPECT_EQ(table.header(),
            (std::vector<std::string>{"time_s", "rate_dph", "temperature_c", "drift_dph",
                                      "drift_est", "drift_sd", "compensated"}));
  EXPECT_GT(table.Column("drift_sd").minCoeff(), 0.0);
  ASSERT_EQ(table.rows(), 600);
  const auto input = io::CsvTable::Read(Dir() + "/test.csv");
  for (const char* c : {"time_s", "rate_dph", "temperature_c", "drift_dph"}) {
    EXPECT_EQ(table.Column(c), input.Column(c)) << c;
  }
  const Eigen::VectorXd estimate = table.Column("drift_est");
  EXPECT_EQ(table.Column("compensated"), (input.Column("rate_dph") - estimate).eval());
  const io::LoadedModel loaded = io::ReadModelFile(Dir() + "/ms.json");
  EXPECT_EQ(estimate, drift::EstimateDrift(loaded.model, input.Column("temperature_c")));
  // On a log it never saw, the estimate tracks the true drift far better than zero does.
  const Eigen::VectorXd truth = input.Column("drift_dph");
  EXPECT_LT(Rms(estimate - truth), 0.5 * Rms(truth.array() - truth.mean()));
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["command"], "compensate");
  EXPECT_EQ(json["model"]["temperature_column"], "temperature_c");
  EXPECT_LT(json["std_after"].get<double>(), json["std_before"].get<double>());
  EXPECT_FALSE(json.contains("truth"));
}

TEST_F(CompensateCli, SaysWhereTheTemperatureLeavesTheTrainingRange) {
  const io::LoadedModel loaded = io::ReadModelFile(Dir() + "/ms.json");
  const auto train = io::CsvTable::Read(Dir() + "/train.csv");
  EXPECT_EQ(loaded.model.temperature_min_c, train.Column("temperature_c").minCoeff());
  EXPECT_EQ(loaded.model.temperature_max_c, train.Column("temperature_c").maxCoeff());
  auto run = [&](const std::string& csv) {
    const std::string out = Dir() + "/range_out.csv";
    const auto r =
        test::RunCli("compensate '" + Dir() + "/ms.json' '" + csv + "' -o '" + out + "'");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
    return std::make_pair(r.out, json["outside_training_temperature_share"].get<double>());
  };
  const auto [inside_out, inside] = run(Dir() + "/test.csv");
  EXPECT_EQ(inside, 0.0);
  EXPECT_EQ(inside_out.find("note:"), std::string::npos) << inside_out;
  // The same log 10 degC warmer: the upper part of the cycle is beyond anything seen in training.
  const auto input = io::CsvTable::Read(Dir() + "/test.csv");
  const Eigen::VectorXd warmer = (input.Column("temperature_c").array() + 10.0).matrix();
  io::WriteCsv(Dir() + "/warmer.csv",
               {{"rate_dph", input.Column("rate_dph")}, {"temperature_c", warmer}});
  const auto [outside_out, outside] = run(Dir() + "/warmer.csv");
  const double expected =
      static_cast<double>((warmer.array() > loaded.model.temperature_max_c).count()) /
      static_cast<double>(warmer.size());
  EXPECT_GT(expected, 0.1);
  EXPECT_EQ(outside, expected);
  EXPECT_NE(outside_out.find("outside the training temperature range"), std::string::npos)
      << outside_out;
}

TEST_F(CompensateCli, TruthColumnGivesTheShareOfTheDriftRemoved) {
  const std::string out = Dir() + "/truth.csv";
  const auto r = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                              "/test.csv' --truth drift_dph -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = io::CsvTable::Read(out);
  const Eigen::VectorXd truth = table.Column("drift_dph");
  const double removed = 100.0 * (1.0 - Rms(truth - table.Column("drift_est")) / Rms(truth));
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["truth"]["column"], "drift_dph");
  EXPECT_NEAR(json["truth"]["removed_percent"].get<double>(), removed, 1e-9);
  EXPECT_EQ(json["truth"]["rms"].get<double>(), Rms(truth));
  char line[64];
  std::snprintf(line, sizeof line, "(%.1f %% removed)", removed);
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out;
}

// What compensation did to the output: mean, RMS, std and slow variation before and after, in
// the console and the sidecar, the library's figures (drift::SummariseCompensation).
TEST_F(CompensateCli, ReportsMeanRmsAndSlowVariationBeforeAndAfter) {
  // 30 min at 1 Hz: three 10-min blocks.
  io::WriteFileAtomically(Dir() + "/long.csv", test::ThermalLogCsv(1800, 3));
  const std::string out = Dir() + "/long_out.csv";
  const auto r = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() + "/long.csv' -o '" +
                              out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = io::CsvTable::Read(out);
  const drift::CompensationSummary s = drift::SummariseCompensation(
      table.Column("rate_dph"), table.Column("compensated"), 1.0);
  ASSERT_EQ(s.blocks, 3);
  EXPECT_NE(r.out.find("rate_dph (dph), 1800 samples:\n"), std::string::npos) << r.out;
  char line[160];
  std::snprintf(line, sizeof line, "  %-16s %14.6g %14.6g\n", "mean", s.before.mean, s.after.mean);
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out << line;
  std::snprintf(line, sizeof line, "  %-16s %14.6g %14.6g  (RMS about their mean of 3 means of "
                "600-s blocks)\n", "slow variation", s.before.slow, s.after.slow);
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out << line;
  EXPECT_NE(r.out.find("  RMS "), std::string::npos) << r.out;
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["before"]["mean"].get<double>(), s.before.mean);
  EXPECT_EQ(json["after"]["mean"].get<double>(), s.after.mean);
  EXPECT_EQ(json["before"]["rms"].get<double>(), s.before.rms);
  EXPECT_EQ(json["after"]["std"].get<double>(), s.after.std);
  EXPECT_EQ(json["std_after"].get<double>(), s.after.std);
  EXPECT_EQ(json["before"]["slow_variation"].get<double>(), s.before.slow);
  EXPECT_EQ(json["after"]["slow_variation"].get<double>(), s.after.slow);
  EXPECT_EQ(json["slow_variation_block_s"].get<double>(), 600.0);
  EXPECT_EQ(json["slow_variation_blocks"].get<int>(), 3);
  // The compensation removes slow drift here.
  EXPECT_LT(s.after.slow, s.before.slow);

  // A 10-min log has one block: the slow variation is not measured, and says so.
  const std::string short_out = Dir() + "/short_out.csv";
  const auto short_run = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                                      "/test.csv' -o '" + short_out + "'");
  ASSERT_EQ(short_run.exit_code, 0) << short_run.err;
  EXPECT_NE(short_run.out.find("n/a"), std::string::npos) << short_run.out;
  EXPECT_NE(short_run.out.find("not measured: the log is shorter than 2 blocks of 600 s"),
            std::string::npos)
      << short_run.out;
  const auto short_json = nlohmann::json::parse(io::ReadTextFile(short_out + ".json"));
  EXPECT_TRUE(short_json["before"]["slow_variation"].is_null());
}

// A temperature in ADC counts is named before the work, with what the tool assumes.
TEST_F(CompensateCli, WarnsUpFrontOfATemperatureInCounts) {
  const auto input = io::CsvTable::Read(Dir() + "/test.csv");
  const Eigen::VectorXd counts = (input.Column("temperature_c").array() * 512.0 + 52000.0).round();
  io::WriteCsv(Dir() + "/counts.csv",
               {{"rate_dph", input.Column("rate_dph")}, {"temperature_c", counts}});
  const auto r = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                              "/counts.csv' -o '" + Dir() + "/counts_out.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string warning = "warning: " + Dir() + "/counts.csv: temperature column "
                              "'temperature_c' runs from ";
  EXPECT_EQ(r.out.rfind(warning, 0), 0u) << r.out;  // the first line
  EXPECT_NE(r.out.find("raw ADC counts?; it is taken as degC as given"), std::string::npos)
      << r.out;
  // A degC log has no such warning.
  const auto clean = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() +
                                  "/test.csv' -o '" + Dir() + "/clean_out.csv'");
  EXPECT_EQ(clean.out.find("warning: " + Dir() + "/test.csv"), std::string::npos) << clean.out;
}

TEST_F(CompensateCli, RunsOnALogWithOnlyTheModelsColumns) {
  const auto input = io::CsvTable::Read(Dir() + "/test.csv");
  io::WriteCsv(Dir() + "/minimal.csv", {{"temperature_c", input.Column("temperature_c")},
                                        {"rate_dph", input.Column("rate_dph")}});
  const std::string out = Dir() + "/minimal_out.csv";
  ASSERT_EQ(test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() + "/minimal.csv' -q -o '" +
                         out + "'")
                .exit_code,
            0);
  const auto table = io::CsvTable::Read(out);
  EXPECT_EQ(table.header().size(), 5u);  // and drift_est, drift_sd, compensated
  const io::LoadedModel loaded = io::ReadModelFile(Dir() + "/ms.json");
  EXPECT_EQ(table.Column("drift_est"),
            drift::EstimateDrift(loaded.model, input.Column("temperature_c")));
}

struct BadCase {
  const char* name;
  std::string args;  // %DIR% is substituted
  int exit_code;
  const char* message;
};

TEST_F(CompensateCli, BadInputGivesOneLineErrorAndNoOutput) {
  io::WriteFileAtomically(Dir() + "/no_temp.csv", "time_s,rate_dph\n0,1\n1,2\n");
  io::WriteFileAtomically(Dir() + "/no_rate.csv", "temperature_c\n20\n21\n");
  io::WriteFileAtomically(Dir() + "/nan.csv", "rate_dph,temperature_c\n1,20\n2,nan\n3,22\n");
  io::WriteFileAtomically(Dir() + "/twice.csv",
                          "rate_dph,temperature_c,drift_est\n1,20,0\n2,21,0\n");
  std::string damaged = io::ReadTextFile(Dir() + "/ms.json");
  const size_t p = damaged.find("\"format_version\"");
  damaged.replace(p, 16, "\"format_versions\"");
  io::WriteFileAtomically(Dir() + "/damaged.json", damaged);
  const std::vector<BadCase> cases = {
      {"missing model", "compensate %DIR%/nope.json %DIR%/test.csv", 2, "no such file"},
      {"missing input", "compensate %DIR%/ms.json %DIR%/nope.csv", 2, "no such file"},
      {"predict model", "compensate %DIR%/pred.json %DIR%/test.csv", 2, "use 'gyrodrift predict'"},
      {"not a model", "compensate %DIR%/test.csv %DIR%/test.csv", 3, "not a gyrodrift model file"},
      {"edited model", "compensate %DIR%/damaged.json %DIR%/test.csv", 3, "format_version"},
      {"temperature missing", "compensate %DIR%/ms.json %DIR%/no_temp.csv", 3,
       "model needs column 'temperature_c' (trained with --temperature temperature_c); "},
      {"target missing", "compensate %DIR%/ms.json %DIR%/no_rate.csv", 3,
       "model needs column 'rate_dph' (trained with --target rate_dph); "},
      {"nan temperature", "compensate %DIR%/ms.json %DIR%/nan.csv", 3, "data row 2"},
      {"unknown truth column", "compensate %DIR%/ms.json %DIR%/test.csv --truth truth", 2,
       "column 'truth' not found"},
      {"truth is a temperature", "compensate %DIR%/ms.json %DIR%/test.csv --truth temperature_c", 2,
       "--truth = temperature_c: must be another column than the model's target and "
       "temperatures"},
      {"zero rate", "compensate %DIR%/ms.json %DIR%/test.csv --rate-hz 0", 2,
       "--rate-hz: 0 is no sample rate"},
      {"truth is the target", "compensate %DIR%/ms.json %DIR%/test.csv --truth rate_dph", 2,
       "--truth = rate_dph: must be another column than the model's target and temperatures"},
      {"already compensated", "compensate %DIR%/ms.json %DIR%/twice.csv", 3,
       "already has a column 'drift_est'"},
  };
  const std::string out = Dir() + "/bad.csv";
  for (const auto& c : cases) {
    const auto r = test::RunCli(test::Substitute(c.args, {{"%DIR%", Dir()}}) + " -o " + out);
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
  const auto r = test::RunCli("compensate '" + Dir() + "/ms.json' '" + Dir() + "/test.csv' -o '" +
                              Dir() + "/no/dir/c.csv'");
  EXPECT_EQ(r.exit_code, 4) << r.err;
}

TEST(CompensateHelp, ShowsAWorkedExample) {
  const auto r = test::RunCli("compensate --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("gyrodrift compensate model.json test.csv"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gyrodrift

namespace gyrodrift {
namespace {

TEST(CompensateCliChannels, TwoTemperatureColumnsFitCompensateAndEvaluate) {
  const std::string dir = test::TempDir("cli_compensate_channels");
  const io::CsvTable log = io::CsvTable::Parse(test::ThermalLogCsv(3000, 5), "log");
  Eigen::VectorXd board(log.rows());
  drift::FirstOrderLag(log.Column("temperature_c"), 150.0, 1.0, board);
  board.array() += 3.0;
  io::WriteCsv(dir + "/two.csv", {{"time_s", log.Column("time_s")},
                                  {"rate_dph", log.Column("rate_dph")},
                                  {"temperature_c", log.Column("temperature_c")},
                                  {"board_c", board},
                                  {"drift_dph", log.Column("drift_dph")}});
  io::WriteCsv(dir + "/one.csv", {{"rate_dph", log.Column("rate_dph")},
                                  {"temperature_c", log.Column("temperature_c")}});
  const std::string fit = "fit '" + dir + "/two.csv' -t rate_dph -T temperature_c,board_c " +
                          "--mode compensate ";
  auto r = test::RunCli(fit + "-o '" + dir + "/m.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("2 temperature channels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("calibration:"), std::string::npos) << r.out;
  const io::LoadedModel loaded = io::ReadModelFile(dir + "/m.json");
  EXPECT_EQ(loaded.info.temperature_column, "temperature_c,board_c");
  r = test::RunCli("compensate '" + dir + "/m.json' '" + dir + "/two.csv' --truth drift_dph -o '" +
                   dir + "/c.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvTable out = io::CsvTable::Read(dir + "/c.csv");
  EXPECT_TRUE(out.HasColumn("drift_sd"));
  // The second column is required by name.
  r = test::RunCli("compensate '" + dir + "/m.json' '" + dir + "/one.csv' -o '" + dir + "/c1.csv'");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("board_c"), std::string::npos) << r.err;
  // A method of one channel says so; a repeated column too.
  r = test::RunCli(fit + "-m poly -o '" + dir + "/p.json'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = test::RunCli("fit '" + dir + "/two.csv' -t rate_dph -T temperature_c,temperature_c " +
                   "--mode compensate -o '" + dir + "/r.json'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // evaluate takes both channels for the identified methods, and refuses a one-channel method
  // before any fit.
  const std::string evaluate = "evaluate '" + dir + "/two.csv' -t rate_dph -T temperature_c,board_c " +
                               "--truth drift_dph --mode compensate ";
  r = test::RunCli(evaluate + "--methods thermal -o '" + dir + "/e.csv'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli(evaluate + "--methods thermal,poly -o '" + dir + "/e2.csv'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(test::FileExists(dir + "/e2.csv"));
}

}  // namespace
}  // namespace gyrodrift

namespace gyrodrift {
namespace {

// Three gyro axes in one log (issue 13): one model per axis in one file, each the model a fit of
// that axis alone gives; compensate adds the columns of every axis.
TEST(CompensateCliAxes, SeveralTargetsFitOneFileAndCompensateEveryAxis) {
  const std::string dir = test::TempDir("cli_compensate_axes");
  const io::CsvTable log = io::CsvTable::Parse(test::ThermalLogCsv(3000, 5), "log");
  const Eigen::VectorXd x = log.Column("rate_dph");
  const Eigen::VectorXd y = 0.5 * x.array() + 0.01;
  const Eigen::VectorXd z = -2.0 * x.array();
  io::WriteCsv(dir + "/imu.csv", {{"time_s", log.Column("time_s")},
                                  {"gyro_x", x},
                                  {"gyro_y", y},
                                  {"gyro_z", z},
                                  {"temperature_c", log.Column("temperature_c")}});
  const std::string fit = "fit '" + dir + "/imu.csv' -T temperature_c --mode compensate -q ";
  auto r = test::RunCli(fit + "-t gyro_x,gyro_y,gyro_z -o '" + dir + "/imu.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli(fit + "-t gyro_y -o '" + dir + "/y.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<io::LoadedModel> axes = io::ReadModelFileAxes(dir + "/imu.json");
  ASSERT_EQ(axes.size(), 3u);
  EXPECT_EQ(axes[0].info.target_column, "gyro_x");
  EXPECT_EQ(axes[2].info.target_column, "gyro_z");
  // The y axis of the three-axis file is the one-axis model of gyro_y, to the byte.
  EXPECT_EQ(io::RenderModelFile(axes[1].model, axes[1].info),
            io::RenderModelFile(io::ReadModelFile(dir + "/y.json").model,
                                io::ReadModelFile(dir + "/y.json").info));

  r = test::RunCli("compensate '" + dir + "/imu.json' '" + dir + "/imu.csv' -o '" + dir +
                   "/out.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvTable out = io::CsvTable::Read(dir + "/out.csv");
  for (const char* axis : {"gyro_x", "gyro_y", "gyro_z"}) {
    for (const char* column : {"drift_est_", "drift_sd_", "compensated_"}) {
      EXPECT_TRUE(out.HasColumn(std::string(column) + axis)) << column << axis;
    }
    EXPECT_NE(r.out.find(std::string(axis) + " (dph), "), std::string::npos) << r.out;
  }
  // The three-axis file estimates gyro_y as the one-axis model does.
  r = test::RunCli("compensate '" + dir + "/y.json' '" + dir + "/imu.csv' -o '" + dir +
                   "/y.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(out.Column("drift_est_gyro_y"), io::CsvTable::Read(dir + "/y.csv").Column("drift_est"));
  const auto sidecar = nlohmann::json::parse(io::ReadTextFile(dir + "/out.csv.json"));
  ASSERT_EQ(sidecar["axes"].size(), 3u);
  EXPECT_EQ(sidecar["axes"][2]["model"]["target_column"], "gyro_z");

  // What a several-axis file cannot do says so, before any work.
  r = test::RunCli("compensate '" + dir + "/imu.json' '" + dir + "/imu.csv' --truth gyro_x -o '" +
                   dir + "/t.csv'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("3 axes"), std::string::npos) << r.err;
  r = test::RunCli("predict '" + dir + "/imu.json' '" + dir + "/imu.csv' -o '" + dir + "/p.csv'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("gyro_x, gyro_y, gyro_z"), std::string::npos) << r.err;
  r = test::RunCli(fit + "-t gyro_x,gyro_x -o '" + dir + "/rep.json'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--target"), std::string::npos) << r.err;
  r = test::RunCli(fit + "-t gyro_x,temperature_c -o '" + dir + "/tt.json'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = test::RunCli("evaluate '" + dir + "/imu.csv' -t gyro_x,gyro_y -T temperature_c "
                   "--mode compensate -o '" + dir + "/e.csv'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  for (const char* name : {"t.csv", "p.csv", "rep.json", "tt.json", "e.csv"}) {
    EXPECT_FALSE(test::FileExists(dir + "/" + name)) << name;
  }
  // A log missing one axis is refused by name.
  io::WriteCsv(dir + "/xy.csv", {{"gyro_x", x}, {"gyro_y", y},
                                 {"temperature_c", log.Column("temperature_c")}});
  r = test::RunCli("compensate '" + dir + "/imu.json' '" + dir + "/xy.csv' -o '" + dir +
                   "/xy_out.csv'");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("gyro_z"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrodrift
