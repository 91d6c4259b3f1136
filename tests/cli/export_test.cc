// gyrodrift export, run as a user would: fit compensate-mode models on a simulated 8-h chamber
// log (thermal, thermal on two temperature channels, ms-elm, thermal referenced to 25 degC),
// compensate a second log, export each model as C (double and --float), compile a small driver
// with the system C compiler (-std=c99 -Wall -Wextra -Werror -pedantic, no -lm) that steps the
// header through the whole log, and compare with compensate's drift_est: max error / RMS(drift_est)
// <= 1e-9 in double, <= 1e-5 in float, also on a log 40 K warmer than the calibration (the powers'
// tangent continuation). The measured errors are printed ("measured: ..."; docs/firmware.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "gyrodrift/drift/features.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/firmware/export.h"
#include "gyrodrift/io/model_file.h"
#include "support/firmware_driver.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

std::string Quote(const std::string& s) { return "'" + s + "'"; }

double Rms(const Eigen::VectorXd& v) {
  return std::sqrt(v.squaredNorm() / static_cast<double>(v.size()));
}

class ExportCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_export"));
    const std::string& d = *dir_;
    ASSERT_EQ(
        test::RunCli("simulate --duration 8h --seed 3 -q -o " + Quote(d + "/train.csv")).exit_code,
        0);
    ASSERT_EQ(test::RunCli("simulate --profile chamber-b --duration 8h --seed 4 -q -o " +
                           Quote(d + "/test.csv"))
                  .exit_code,
              0);
    // A second channel, a board that lags the case, warmed by its own 2-h load cycle (a mere lag
    // of the case would make the candidate regressors collinear), with a drift of its own; and
    // the test log 40 K warmer than the calibration's programme.
    for (const char* run : {"train", "test"}) {
      const io::CsvTable t = io::CsvTable::Read(d + "/" + run + ".csv");
      const Eigen::VectorXd temperature = t.Column("temperature_c");
      Eigen::VectorXd board(temperature.size());
      drift::FirstOrderLag(temperature, 900.0, 1.0, board);
      for (Eigen::Index i = 0; i < board.size(); ++i) {
        board[i] += 4.0 + 2.0 * std::sin(2.0 * 3.141592653589793 * static_cast<double>(i) / 7200.0);
      }
      const Eigen::VectorXd rate =
          t.Column("rate_dph") + 0.01 * (board.array() - 25.0).square().matrix() / 25.0;
      io::WriteCsv(d + "/" + run + "2.csv",
                   {{"rate_dph", rate}, {"temperature_c", temperature}, {"board_c", board}});
      if (std::string(run) == "test") {
        io::WriteCsv(d + "/warm.csv", {{"rate_dph", t.Column("rate_dph")},
                                       {"temperature_c", (temperature.array() + 40.0).matrix()}});
      }
    }
    const std::string fit =
        "fit " + Quote(d + "/train.csv") + " -t rate_dph -T temperature_c --mode compensate -q ";
    ASSERT_EQ(test::RunCli(fit + "-o " + Quote(d + "/thermal.json")).exit_code, 0);
    ASSERT_EQ(test::RunCli(fit + "-m ms-elm -I 10 --realisations 20 -o " + Quote(d + "/ms.json"))
                  .exit_code,
              0);
    ASSERT_EQ(
        test::RunCli(fit + "--reference-temperature 25 -o " + Quote(d + "/ref.json")).exit_code, 0);
    ASSERT_EQ(test::RunCli("fit " + Quote(d + "/train2.csv") +
                           " -t rate_dph -T temperature_c,board_c --mode compensate -q -o " +
                           Quote(d + "/two.json"))
                  .exit_code,
              0);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }

  // compensate's drift_est of `model` on `log`.
  static Eigen::VectorXd DriftEst(const std::string& model, const std::string& log) {
    const std::string out = Dir() + "/" + model + "_" + log + "_est.csv";
    const auto r = test::RunCli("compensate " + Quote(Dir() + "/" + model + ".json") + " " +
                                Quote(Dir() + "/" + log + ".csv") + " -q -o " + Quote(out));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return io::CsvTable::Read(out).Column("drift_est");
  }

  // Exports `model` (extra flags `flags`), compiles a driver against it and runs it over the
  // temperature columns of `log`; returns axis 0's estimates.
  static Eigen::VectorXd RunHeader(const std::string& model, const std::string& log,
                                   const std::string& prefix, const std::string& flags,
                                   const std::string& compiler = test::kCCompiler,
                                   const std::string& language_flags = test::kCFlags) {
    const std::string header = Dir() + "/" + prefix + ".h";
    const auto exported =
        test::RunCli("export " + Quote(Dir() + "/" + model + ".json") + " --format c --prefix " +
                     prefix + " " + flags + " -o " + Quote(header));
    EXPECT_EQ(exported.exit_code, 0) << exported.err;
    EXPECT_NE(exported.out.find("wrote " + header), std::string::npos) << exported.out;
    const io::CsvTable table = io::CsvTable::Read(Dir() + "/" + log + ".csv");
    const std::string columns =
        io::ReadModelFile(Dir() + "/" + model + ".json").info.temperature_column;
    std::vector<Eigen::VectorXd> t;
    for (size_t start = 0;;) {
      const size_t comma = columns.find(',', start);
      t.push_back(table.Column(columns.substr(start, comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    Eigen::MatrixXd temperature(table.rows(), static_cast<Eigen::Index>(t.size()));
    for (size_t c = 0; c < t.size(); ++c) temperature.col(static_cast<Eigen::Index>(c)) = t[c];
    const Eigen::MatrixXd out =
        test::RunFirmwareHeader(header, prefix, temperature, Dir(), compiler, language_flags);
    return out.cols() > 0 ? Eigen::VectorXd(out.col(0)) : Eigen::VectorXd();
  }

  // Max |header - drift_est| / RMS(drift_est), printed for docs/firmware.md.
  static double Error(const Eigen::VectorXd& header, const Eigen::VectorXd& est,
                      const std::string& label) {
    EXPECT_EQ(header.size(), est.size()) << label;
    if (header.size() != est.size()) return INFINITY;
    const double relative = (header - est).cwiseAbs().maxCoeff() / Rms(est);
    const Eigen::VectorXd centred = est.array() - est.mean();
    std::cout << "measured: " << label << ": max error " << (header - est).cwiseAbs().maxCoeff()
              << ", / RMS(drift_est) " << relative << ", / SD(drift_est) "
              << (header - est).cwiseAbs().maxCoeff() / Rms(centred) << "\n";
    return relative;
  }

  static std::string* dir_;
};
std::string* ExportCli::dir_ = nullptr;

struct Case {
  std::string model, log;
};

TEST_F(ExportCli, HeaderReproducesCompensateInDoubleAndFloat) {
  ASSERT_TRUE(std::filesystem::exists(test::kCCompiler))
      << "no C compiler (cc, gcc or clang) was found when the tests were configured";
  for (const Case& c : {Case{"thermal", "test"}, Case{"thermal", "warm"}, Case{"two", "test2"},
                        Case{"ms", "test"}, Case{"ref", "test"}}) {
    const std::string label = c.model + " on " + c.log;
    const Eigen::VectorXd est = DriftEst(c.model, c.log);
    EXPECT_LE(
        Error(RunHeader(c.model, c.log, "d_" + c.model + "_" + c.log, ""), est, label + ", double"),
        1e-9);
    EXPECT_LE(Error(RunHeader(c.model, c.log, "f_" + c.model + "_" + c.log, "--float"), est,
                    label + ", float"),
              1e-5);
  }
}

TEST_F(ExportCli, TheHeaderIsAlsoValidCpp) {
  const Eigen::VectorXd est = DriftEst("two", "test2");
  EXPECT_LE(Error(RunHeader("two", "test2", "cpp_two", "", test::kCxxCompiler,
                            "-x c++ -std=c++17 -O2 -Wall -Wextra -Werror -pedantic"),
                  est, "two on test2, double, compiled as C++"),
            1e-9);
}

TEST_F(ExportCli, TheCasesExerciseWhatTheyClaim) {
  // The warm log takes a state beyond its calibrated range, where the powers continue along
  // their tangent; the two-channel model uses the board channel; ms-elm has several sub-models.
  const io::LoadedModel thermal = io::ReadModelFile(Dir() + "/thermal.json");
  const Eigen::VectorXd warm = io::CsvTable::Read(Dir() + "/warm.csv").Column("temperature_c");
  bool beyond = false;
  for (const auto& sub : thermal.model.sub_models) {
    const drift::ThermalRegression& t = *sub.thermal;
    ASSERT_GE(t.max_power, 2);
    for (const auto& s : t.states) {
      Eigen::VectorXd level = warm, lagged(warm.size());
      for (int o = 0; o < t.order; ++o) {
        drift::FirstOrderLag(level, s.tau_s, 1.0 / t.rate_hz, lagged);
        level = lagged;
      }
      const double z_max = (level.maxCoeff() - t.centre_c[0]) / t.scale_k[0];
      beyond = beyond || z_max > s.level_max + 0.3;
    }
  }
  EXPECT_TRUE(beyond) << thermal.model.Summary();
  const io::LoadedModel two = io::ReadModelFile(Dir() + "/two.json");
  const auto& t2 = *two.model.sub_models[0].thermal;
  EXPECT_TRUE(t2.static_power[1] > 0 || std::any_of(t2.states.begin(), t2.states.end(),
                                          [](const auto& s) { return s.channel == 1; }))
      << t2.Summary();
  EXPECT_GE(io::ReadModelFile(Dir() + "/ms.json").model.sub_models.size(), 2u);
}

TEST_F(ExportCli, CoefficientsJsonAndRefusals) {
  const std::string out = Dir() + "/coefficients.json";
  const auto r = test::RunCli("export " + Quote(Dir() + "/two.json") +
                              " --format json-coefficients -o " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("json-coefficients: 1 axis, 2 temperature channels"), std::string::npos)
      << r.out;
  const std::string text = io::ReadTextFile(out);
  const io::LoadedModel two = io::ReadModelFile(Dir() + "/two.json");
  EXPECT_EQ(text,
            firmware::RenderCoefficientsJson({two}, {.format = firmware::ExportFormat::kCoefficientsJson}));
  const auto json = nlohmann::json::parse(text);
  EXPECT_EQ(json["channels"], (std::vector<std::string>{"temperature_c", "board_c"}));

  // A learner-based compensate model: refused in one line naming the reason, nothing written.
  ASSERT_EQ(test::RunCli("fit " + Quote(Dir() + "/train.csv") +
                         " -t rate_dph -T temperature_c --mode compensate -m poly -q -o " +
                         Quote(Dir() + "/poly.json"))
                .exit_code,
            0);
  test::ExpectCleanFailure(
      test::RunCli("export " + Quote(Dir() + "/poly.json") + " -o " + Quote(Dir() + "/poly.h")), 2,
      "sub-model 'signal' is a poly learner on thermal features", Dir() + "/poly.h", "export poly");
  // Two gyros logged alike (a copy of one model file stands for the second): one axis name for
  // two axes, and one temperature channel for two sensors. Refused in both formats that name axes.
  std::filesystem::copy_file(Dir() + "/two.json", Dir() + "/copy.json",
                             std::filesystem::copy_options::overwrite_existing);
  for (const char* format : {"c", "json-coefficients"}) {
    test::ExpectCleanFailure(
        test::RunCli("export " + Quote(Dir() + "/two.json") + " " + Quote(Dir() + "/copy.json") +
                     " --format " + format + " -o " + Quote(Dir() + "/twice.h")),
        2, "axis 1 (rate_dph) has the target and the temperature column 'temperature_c' of axis 0",
        Dir() + "/twice.h", format);
  }
}

}  // namespace
}  // namespace gyrodrift

namespace gyrodrift {
namespace {

// A model file of two gyro axes (fit --target a,b) exports to one header whose step fills both
// axes as compensate writes drift_est_<axis>; the axes share the temperature channels.
TEST(ExportCliAxes, OneHeaderForEveryAxisOfAModelFile) {
  const std::string d = test::TempDir("cli_export_axes");
  const std::string q = "'";
  const io::CsvTable log = io::CsvTable::Parse(test::ThermalLogCsv(4000, 8), "log");
  Eigen::VectorXd board(log.rows());
  drift::FirstOrderLag(log.Column("temperature_c"), 300.0, 1.0, board);
  const Eigen::VectorXd a = log.Column("rate_dph");
  const Eigen::VectorXd b = 0.3 * a.array() + 0.02 * (board.array() - 20.0);
  io::WriteCsv(d + "/imu.csv", {{"gyro_a", a},
                                {"gyro_b", b},
                                {"temperature_c", log.Column("temperature_c")},
                                {"board_c", board}});
  ASSERT_EQ(test::RunCli("fit " + q + d + "/imu.csv' -t gyro_a,gyro_b -T temperature_c,board_c "
                         "--mode compensate -q -o " + q + d + "/imu.json'")
                .exit_code,
            0);
  auto r = test::RunCli("compensate " + q + d + "/imu.json' " + q + d + "/imu.csv' -q -o " + q +
                        d + "/out.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli("export " + q + d + "/imu.json' --prefix imu -o " + q + d + "/imu.h'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::CsvTable out = io::CsvTable::Read(d + "/out.csv");
  Eigen::MatrixXd temperature(out.rows(), 2);
  temperature << out.Column("temperature_c"), out.Column("board_c");
  const Eigen::MatrixXd header = test::RunFirmwareHeader(d + "/imu.h", "imu", temperature, d);
  ASSERT_EQ(header.cols(), 2);
  for (int axis = 0; axis < 2; ++axis) {
    const Eigen::VectorXd est = out.Column(axis == 0 ? "drift_est_gyro_a" : "drift_est_gyro_b");
    EXPECT_LE((header.col(axis) - est).cwiseAbs().maxCoeff() / Rms(est), 1e-9) << axis;
  }
  std::filesystem::remove_all(d);
}

// Two gyros of three axes each (as a ULog's two sensor_gyro instances give them): fit each, then
// one PX4 parameter file for both, each axis' autopilot form and its share of the full model
// said; without device ids, or with the axes of one gyro only, it is refused and nothing written.
TEST(ExportCliPx4, TwoGyrosFromOneFitEachToOneParameterFile) {
  const std::string d = test::TempDir("cli_export_px4");
  const std::string q = "'";
  for (int gyro = 0; gyro < 2; ++gyro) {
    const io::CsvTable log = io::CsvTable::Parse(test::ThermalLogCsv(3600, 20 + gyro), "log");
    const Eigen::VectorXd r = log.Column("rate_dph");
    const std::string csv = d + "/gyro" + std::to_string(gyro) + ".csv";
    io::WriteCsv(csv, {{"time_s", log.Column("time_s")},
                       {"x_dph", r},
                       {"y_dph", (-0.5 * r).eval()},
                       {"z_dph", (0.2 * r).eval()},
                       {"temperature_c", log.Column("temperature_c")}});
    ASSERT_EQ(test::RunCli("fit " + q + csv + "' -t x_dph,y_dph,z_dph -T temperature_c --mode "
                           "compensate -q -o " + q + d + "/gyro" + std::to_string(gyro) + ".json'")
                  .exit_code,
              0);
  }
  const std::string models = q + d + "/gyro0.json' " + q + d + "/gyro1.json'";
  const std::string out = d + "/tc.params";
  const test::CommandResult r = test::RunCli("export " + models +
                                             " --format px4 --device-id 2490378,2621450 -o " + q +
                                             out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("TC_G1 axis 2 (z_dph): "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the full model removes"), std::string::npos) << r.out;
  const std::string text = io::ReadTextFile(out);
  std::vector<io::LoadedModel> axes = io::ReadModelFileAxes(d + "/gyro0.json");
  for (io::LoadedModel& axis : io::ReadModelFileAxes(d + "/gyro1.json")) axes.push_back(axis);
  EXPECT_EQ(text, firmware::RenderPx4Params(axes, {2490378, 2621450}));
  EXPECT_NE(text.find("1\t1\tTC_G1_ID\t2621450\t6\n"), std::string::npos) << text;
  const std::string out2 = d + "/bad.params";
  test::ExpectCleanFailure(test::RunCli("export " + models + " --format px4 -o " + q + out2 + "'"),
                           2, "--device-id = none", out2, "no device id");
  test::ExpectCleanFailure(test::RunCli("export " + q + d + "/gyro0.json' --format px4 "
                                        "--device-id 1,2 -o " + q + out2 + "'"),
                           2, "PX4 calibrates 1 to 3 gyros of 3 axes each", out2, "one gyro");
  // A typo that names one model twice, or one sensor twice, would run one gyro's model on another.
  test::ExpectCleanFailure(
      test::RunCli("export " + models + " --format px4 --device-id 7,7 -o " + q + out2 + "'"), 2,
      "--device-id = 7,7: must be one DEVID per gyro instance, each once (7 twice)", out2,
      "one device id twice");
  test::ExpectCleanFailure(
      test::RunCli("export " + q + d + "/gyro0.json' " + q + d + "/./gyro0.json' -o " + q + d +
                   "/twice.h'"),
      2, "model files " + d + "/gyro0.json and " + d + "/./gyro0.json are one file", d + "/twice.h",
      "one model file twice");
  std::filesystem::remove_all(d);
}

}  // namespace
}  // namespace gyrodrift
