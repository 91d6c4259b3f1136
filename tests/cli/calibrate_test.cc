// gyrodrift calibrate on a small fleet built from the independent family's shipped units (each
// axis of an IMU is another unit of the family, with its own temperature sensor): the per-unit
// outputs, the fleet table and report, agreement with `fit`, rerun skipping, a failing unit, and
// bad manifests named by line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "regression/allan/allan_fixtures.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

namespace fs = std::filesystem;

io::CsvTable UnitFile(const std::string& name) {
  return io::CsvTable::Read(
      allan::fixtures::Gunzip(test::TestDataPath("gyro_thermal_family/units/" + name), name));
}

// An IMU log whose axis x is family unit `ux` and axis y unit `uy` (calibration or mission run).
void WriteImuLog(const std::string& path, int ux, int uy, bool mission) {
  auto file = [&](int u) {
    return "unit" + std::to_string(u) + (mission ? "_test8h_mission.csv.gz" : "_train16h.csv.gz");
  };
  const io::CsvTable x = UnitFile(file(ux)), y = UnitFile(file(uy));
  std::vector<io::CsvColumn> columns = {{"time_s", x.Column("time_s")},
                                        {"gyro_x", x.Column("rate_dph")},
                                        {"gyro_y", y.Column("rate_dph")},
                                        {"temp_x", x.Column("temperature_c")},
                                        {"temp_y", y.Column("temperature_c")}};
  if (mission) {
    const auto truth = [](int u) {
      return UnitFile("unit" + std::to_string(u) + "_test8h_mission_truth.csv.gz")
          .Column("drift_dph");
    };
    columns.push_back({"drift_x", truth(ux)});
    columns.push_back({"drift_y", truth(uy)});
  }
  io::WriteCsv(path, columns);
}

const char* kAxes = R"(
[[axis]]
target = "gyro_x"
temperature = "temp_x"
truth = "drift_x"

[[axis]]
target = "gyro_y"
temperature = ["temp_y"]
truth = "drift_y"
)";

class CalibrateCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_calibrate"));
    fs::create_directories(Dir() + "/logs");
    // Three IMUs: (1, 2), (3, 4), (2, 3).
    const int pairs[3][2] = {{1, 2}, {3, 4}, {2, 3}};
    for (int i = 0; i < 3; ++i) {
      const std::string sn = "SN" + std::to_string(i + 1);
      WriteImuLog(Dir() + "/logs/" + sn + "_cal.csv", pairs[i][0], pairs[i][1], false);
      WriteImuLog(Dir() + "/logs/" + sn + "_ver.csv", pairs[i][0], pairs[i][1], true);
    }
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }
  static std::string Manifest(const std::string& name, const std::string& limits, int units) {
    std::string text = "method = \"thermal\"\nrate_unit = \"dph\"\n" + limits + kAxes;
    for (int i = 1; i <= units; ++i) {
      const std::string sn = "SN" + std::to_string(i);
      text += "\n[[unit]]\nserial = \"" + sn + "\"\ncalibration = \"logs/" + sn +
              "_cal.csv\"\nverification = [\"logs/" + sn + "_ver.csv\"]\n";
    }
    const std::string path = Dir() + "/" + name;
    io::WriteFileAtomically(path, text);
    return path;
  }
  static std::string* dir_;
};
std::string* CalibrateCli::dir_ = nullptr;

TEST_F(CalibrateCli, CalibratesEveryUnitAndAxisAndMatchesFit) {
  const std::string manifest =
      Manifest("fleet.toml", "[limits]\nremoved_share_min = 0.5\nbias_instability_dph = 1.0\n", 3);
  const std::string out = Dir() + "/out";
  auto r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "' --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("3 units: 3 calibrated, 0 skipped"), std::string::npos) << r.out;
  for (const char* sn : {"SN1", "SN2", "SN3"}) {
    for (const char* f : {"model.json", "verification_1_compensated.csv", "allan.csv",
                          "report.html", "summary.json"}) {
      EXPECT_TRUE(test::FileExists(out + "/" + sn + "/" + f)) << sn << "/" << f;
    }
  }
  // The fleet table: one row per unit and axis, every unit above the limit on the family (the
  // identified model removes 81-96 % on units 1-4: docs/drift.md 4.5).
  const std::string csv = io::ReadTextFile(out + "/fleet.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 * 2) << csv;
  EXPECT_EQ(csv.find(",fail,"), std::string::npos) << csv;
  // The per-unit model is the model `fit` writes for the same log and axes.
  r = test::RunCli("fit '" + Dir() + "/logs/SN2_cal.csv' -t gyro_x -T temp_x --mode compensate -q -o '" +
                   Dir() + "/x.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto axes = io::ReadModelFileAxes(out + "/SN2/model.json");
  ASSERT_EQ(axes.size(), 2u);
  const io::LoadedModel fitted = io::ReadModelFile(Dir() + "/x.json");
  const io::CsvTable ver = io::CsvTable::Read(Dir() + "/logs/SN2_ver.csv");
  EXPECT_EQ(drift::EstimateDrift(axes[0].model, ver.Column("temp_x")),
            drift::EstimateDrift(fitted.model, ver.Column("temp_x")));
  const io::CsvTable compensated =
      io::CsvTable::Read(out + "/SN2/verification_1_compensated.csv");
  EXPECT_EQ(compensated.Column("drift_est_gyro_x"),
            drift::EstimateDrift(fitted.model, ver.Column("temp_x")));
  // Reports: structurally sound, the fleet page links each unit's page.
  const std::string fleet_html = io::ReadTextFile(out + "/fleet.html");
  const test::ReportCheck check = test::CheckReportHtml(fleet_html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_NE(fleet_html.find("href=\"SN3/report.html\""), std::string::npos);
  EXPECT_TRUE(test::CheckReportHtml(io::ReadTextFile(out + "/SN1/report.html")).ok());

  // A rerun skips every unit; --force redoes them with the same numbers; a changed log is redone.
  r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "'");
  EXPECT_NE(r.out.find("0 calibrated, 3 skipped"), std::string::npos) << r.out;
  const std::string model_before = io::ReadTextFile(out + "/SN1/model.json");
  r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "' --force --threads 1");
  EXPECT_NE(r.out.find("3 calibrated, 0 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(io::ReadTextFile(out + "/SN1/model.json"), model_before);
  const std::string rows_before = io::ReadTextFile(out + "/fleet.csv");
  std::ofstream(Dir() + "/logs/SN3_ver.csv", std::ios::app) << "";  // same bytes: still skipped
  r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "'");
  EXPECT_NE(r.out.find("0 calibrated, 3 skipped"), std::string::npos) << r.out;
}

// Calibration in two chamber runs, and a verification log whose logger stopped for an hour: the
// runs are fitted as records of one run (the model `fit` gives for the two logs), the
// verification is compensated with the states restarting after the gap (gaps = "split").
TEST_F(CalibrateCli, SeveralCalibrationLogsAndASplitVerification) {
  const io::CsvTable cal = io::CsvTable::Read(Dir() + "/logs/SN1_cal.csv");
  const io::CsvTable ver = io::CsvTable::Read(Dir() + "/logs/SN1_ver.csv");
  const Eigen::Index half = cal.rows() / 2, hour = 3600;
  auto rows = [](const io::CsvTable& t, Eigen::Index first, Eigen::Index count) {
    std::vector<io::CsvColumn> out;
    for (const std::string& name : t.header()) out.push_back({name, t.Column(name).segment(first, count)});
    return out;
  };
  io::WriteCsv(Dir() + "/logs/R_cal_a.csv", rows(cal, 0, half));
  io::WriteCsv(Dir() + "/logs/R_cal_b.csv", rows(cal, half, cal.rows() - half));
  // The verification without its third hour.
  std::vector<io::CsvColumn> gap = rows(ver, 0, 2 * hour);
  const std::vector<io::CsvColumn> rest = rows(ver, 3 * hour, ver.rows() - 3 * hour);
  for (size_t c = 0; c < gap.size(); ++c) {
    gap[c].values.conservativeResize(2 * hour + rest[c].values.size());
    gap[c].values.tail(rest[c].values.size()) = rest[c].values;
  }
  io::WriteCsv(Dir() + "/logs/R_ver_gap.csv", gap);
  const std::string manifest = Dir() + "/records.toml";
  io::WriteFileAtomically(manifest, std::string("gaps = \"split\"\n") + kAxes +
                                        "\n[[unit]]\nserial = \"R1\"\ncalibration = "
                                        "[\"logs/R_cal_a.csv\", \"logs/R_cal_b.csv\"]\n"
                                        "verification = \"logs/R_ver_gap.csv\"\n");
  const std::string out = Dir() + "/out_records";
  auto r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = test::RunCli("fit '" + Dir() + "/logs/R_cal_a.csv' '" + Dir() + "/logs/R_cal_b.csv' " +
                   "-t gyro_x -T temp_x --mode compensate -q -o '" + Dir() + "/r.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto axes = io::ReadModelFileAxes(out + "/R1/model.json");
  const io::LoadedModel fitted = io::ReadModelFile(Dir() + "/r.json");
  ASSERT_TRUE(axes[0].model.sub_models.front().thermal);
  EXPECT_EQ(axes[0].model.sub_models.front().thermal->report.records, 2);
  EXPECT_EQ(axes[0].model.sub_models.front().thermal->coefficients,
            fitted.model.sub_models.front().thermal->coefficients);
  // The verification's estimate restarts after the gap: that of its two pieces.
  const io::CsvTable compensated = io::CsvTable::Read(out + "/R1/verification_1_compensated.csv");
  const Eigen::VectorXd t = ver.Column("temp_x");
  Eigen::VectorXd expected(compensated.rows());
  expected << drift::EstimateDrift(fitted.model, t.head(2 * hour)),
      drift::EstimateDrift(fitted.model, t.tail(ver.rows() - 3 * hour));
  EXPECT_EQ(compensated.Column("drift_est_gyro_x"), expected);
  EXPECT_NE(io::ReadTextFile(out + "/R1/report.html").find("R_cal_a.csv, R_cal_b.csv"),
            std::string::npos);
}

// A duty-cycled calibration log (60 s of every 300 s) under gaps = "carry": the model `fit
// --gaps carry` gives; a verification log with made-up rows is refused (its block means and
// Allan deviation need logged rows).
TEST_F(CalibrateCli, ADutyCycledCalibrationIsFittedOnItsLoggedRows) {
  auto write_bursts = [](const std::string& from, const std::string& to) {
    const io::CsvTable log = io::CsvTable::Read(from);
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = 0; i < log.rows(); ++i) {
      if (i % 300 < 60) keep.push_back(i);
    }
    std::vector<io::CsvColumn> bursts;
    for (const std::string& name : log.header()) {
      const Eigen::VectorXd all = log.Column(name);
      Eigen::VectorXd kept(static_cast<Eigen::Index>(keep.size()));
      for (size_t k = 0; k < keep.size(); ++k) kept[static_cast<Eigen::Index>(k)] = all[keep[k]];
      bursts.push_back({name, kept});
    }
    io::WriteCsv(to, bursts);
  };
  write_bursts(Dir() + "/logs/SN1_cal.csv", Dir() + "/logs/D_cal.csv");
  write_bursts(Dir() + "/logs/SN1_ver.csv", Dir() + "/logs/D_ver.csv");
  const std::string manifest = Dir() + "/carry.toml";
  io::WriteFileAtomically(manifest, std::string("gaps = \"carry\"\n") + kAxes +
                                        "\n[[unit]]\nserial = \"D1\"\ncalibration = "
                                        "\"logs/D_cal.csv\"\nverification = \"logs/SN1_ver.csv\"\n");
  const std::string out = Dir() + "/out_carry";
  auto r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "' -q");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = test::RunCli("fit '" + Dir() + "/logs/D_cal.csv' -t gyro_x -T temp_x --mode compensate " +
                   "--gaps carry -q -o '" + Dir() + "/d.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto axes = io::ReadModelFileAxes(out + "/D1/model.json");
  const io::LoadedModel fitted = io::ReadModelFile(Dir() + "/d.json");
  ASSERT_TRUE(axes[0].model.sub_models.front().thermal);
  EXPECT_EQ(axes[0].model.sub_models.front().thermal->coefficients,
            fitted.model.sub_models.front().thermal->coefficients);
  // A verification logged in bursts: refused, naming the log.
  io::WriteFileAtomically(manifest, std::string("gaps = \"carry\"\n") + kAxes +
                                        "\n[[unit]]\nserial = \"D2\"\ncalibration = "
                                        "\"logs/SN1_cal.csv\"\nverification = \"logs/D_ver.csv\"\n");
  r = test::RunCli("calibrate '" + manifest + "' -o '" + Dir() + "/out_carry2'");
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_NE((r.out + r.err).find("D_ver.csv: gaps = 'carry' fills this verification log's gaps"),
            std::string::npos)
      << r.out << r.err;
}

TEST_F(CalibrateCli, AFailingUnitIsReportedAndTheOthersGoOn) {
  // SN1's verification log loses a value; the limit is one no unit meets.
  fs::create_directories(Dir() + "/bad");
  std::string manifest = Manifest("limits.toml", "[limits]\nresidual_drift_rms = 1e-9\n", 2);
  const std::string out = Dir() + "/out_limits";
  auto r = test::RunCli("calibrate '" + manifest + "' -o '" + out + "'");
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.out.find("fail: unit SN1 axis gyro_x"), std::string::npos) << r.out;
  EXPECT_TRUE(test::FileExists(out + "/fleet.html"));

  std::string text = io::ReadTextFile(Dir() + "/logs/SN2_ver.csv");
  const size_t row = text.find('\n', text.find('\n') + 1);
  text.replace(text.find(',', row) + 1, text.find(',', text.find(',', row) + 1) - text.find(',', row) - 1, "nan");
  io::WriteFileAtomically(Dir() + "/bad/SN2_ver.csv", text);
  std::string broken = io::ReadTextFile(Manifest("broken.toml", "", 2));
  broken.replace(broken.find("logs/SN2_ver.csv"), 16, "bad/SN2_ver.csv");
  io::WriteFileAtomically(Dir() + "/broken.toml", broken);
  r = test::RunCli("calibrate '" + Dir() + "/broken.toml' -o '" + Dir() + "/out_broken'");
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.out.find("error: unit SN2:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 calibrated"), std::string::npos) << r.out;
  EXPECT_TRUE(test::FileExists(Dir() + "/out_broken/SN1/summary.json"));
  EXPECT_FALSE(test::FileExists(Dir() + "/out_broken/SN2/summary.json"));

  // A verification that is the calibration's own log (however spelt) would judge the model on
  // what it was fitted on: that unit is not calibrated.
  std::string own = io::ReadTextFile(Manifest("own.toml", "", 2));
  own.replace(own.find("verification = [\"logs/SN2_ver.csv"), 33,
              "verification = [\"./logs/SN2_ver.csv");
  own.replace(own.find("logs/SN2_cal.csv"), 16, "logs/SN2_ver.csv");
  io::WriteFileAtomically(Dir() + "/own.toml", own);
  r = test::RunCli("calibrate '" + Dir() + "/own.toml' -o '" + Dir() + "/out_own'");
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.out.find("error: unit SN2: logs "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SN2_ver.csv are one file: each log is calibration or verification, once"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(test::FileExists(Dir() + "/out_own/SN2/summary.json"));
}

TEST_F(CalibrateCli, BadManifestsAreNamedByLine) {
  struct Case {
    std::string label, text, message;
  };
  const std::string unit =
      "\n[[unit]]\nserial = \"SN1\"\ncalibration = \"logs/SN1_cal.csv\"\nverification = "
      "\"logs/SN1_ver.csv\"\n";
  const std::vector<Case> cases = {
      {"bad TOML", "method = \n", "bad.toml:1: not valid TOML"},
      {"unknown key", "methd = \"thermal\"\n" + std::string(kAxes) + unit,
       "bad.toml:1: unknown key 'methd'"},
      {"missing file",
       std::string(kAxes) + unit +
           "\n[[unit]]\nserial = \"SN9\"\ncalibration = "
           "\"logs/none.csv\"\nverification = \"logs/SN1_ver.csv\"\n",
       "bad.toml:17: unit 'SN9': log"},
      {"duplicate serial", std::string(kAxes) + unit + unit,
       "bad.toml:17: serial 'SN1' repeats the unit of line 12"},
      {"unknown column", "[[axis]]\ntarget = \"gyro_q\"\ntemperature = \"temp_x\"\n" + unit,
       "bad.toml:5: unit 'SN1':"},
      {"bad method", "method = \"wavelet\"\n" + std::string(kAxes) + unit, "bad.toml:1: method"},
      {"no axis", unit, "no [[axis]] table"},
      {"bad limit", "[limits]\nresidual_drift_rms = -1\n" + std::string(kAxes) + unit,
       "bad.toml:2: 'residual_drift_rms' = -1"},
      {"several calibration logs, not thermal",
       "method = \"ms-elm\"\n" + std::string(kAxes) +
           "\n[[unit]]\nserial = \"SN1\"\n"
           "calibration = [\"logs/SN1_cal.csv\", \"logs/SN2_cal.csv\"]\nverification = "
           "\"logs/SN1_ver.csv\"\n",
       "bad.toml:15: several calibration logs need method = 'thermal', not 'ms-elm'"},
      {"split, not thermal", "method = \"ms-elm\"\ngaps = \"split\"\n" + std::string(kAxes) + unit,
       "bad.toml:2: gaps = 'split' needs method = 'thermal'"},
      {"carry, decomposition",
       "method = \"ms-elm\"\ngaps = \"carry\"\n" + std::string(kAxes) + unit,
       "bad.toml:2: gaps = 'carry' needs a method that fits on the logged rows only"},
      {"bad delimiter", "delimiter = \"pipe\"\n" + std::string(kAxes) + unit,
       "bad.toml:1: delimiter = 'pipe': must be one of auto, comma, tab, semicolon"},
      {"bad hysteresis", "hysteresis = \"sometimes\"\n" + std::string(kAxes) + unit,
       "bad.toml:1: hysteresis = 'sometimes': must be one of auto, on, off"},
      {"hysteresis, not identified",
       "method = \"poly\"\nhysteresis = \"on\"\n" + std::string(kAxes) + unit,
       "bad.toml:2: hysteresis = 'on': must be auto unless"},
      {"reference out of range", "reference_temperature_c = 500\n" + std::string(kAxes) + unit,
       "bad.toml:1: reference_temperature_c = 500: must be in [-100, 200]"},
      {"serial with a slash",
       std::string(kAxes) + "\n[[unit]]\nserial = \"a/b\"\ncalibration = "
                            "\"logs/SN1_cal.csv\"\nverification = \"logs/SN1_ver.csv\"\n",
       "must be usable as a folder"},
      // A unit folder named as a fleet-level file would take its place (case aside).
      {"serial of a fleet file",
       std::string(kAxes) +
           "\n[[unit]]\nserial = \"Fleet.csv\"\n"
           "calibration = \"logs/SN1_cal.csv\"\nverification = \"logs/SN1_ver.csv\"\n",
       "serial 'Fleet.csv' is the name of a file the fleet writes"},
      {"serial with a NUL",
       std::string(kAxes) +
           "\n[[unit]]\nserial = \"a\\u0000b\"\n"
           "calibration = \"logs/SN1_cal.csv\"\nverification = \"logs/SN1_ver.csv\"\n",
       "serial holds a control character"},
  };
  for (const Case& c : cases) {
    io::WriteFileAtomically(Dir() + "/bad.toml", c.text);
    const std::string out = Dir() + "/out_bad";
    const auto r = test::RunCli("calibrate '" + Dir() + "/bad.toml' -o '" + out + "'");
    EXPECT_EQ(r.exit_code, 2) << c.label << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.label << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.label << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.label;
  }
  // The output folder may not hold the logs (the user's data is never written over).
  const auto r = test::RunCli("calibrate '" + Manifest("ok.toml", "", 1) + "' -o '" + Dir() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
}

}  // namespace
}  // namespace gyrodrift
