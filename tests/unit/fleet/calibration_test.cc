// Fleet calibration (fleet/calibration.h) on three short simulated units (2-h chamber runs at
// 1 Hz, calibration and verification of different seeds): the figures of a verification are the
// documented measures of the logs and of the compensated output written beside them; limits fail
// strictly beyond their value; a unit's own error is its row and the other units go on; a finished
// unit is skipped and a damaged one redone; fleet.csv's rows carry the results' values, counts and
// outliers; and 1 or 2 threads give the same files.
#include "gyrodrift/fleet/calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift::fleet {
namespace {

namespace fs = std::filesystem;
namespace sim = gyrodrift::simulation;

constexpr Eigen::Index kCalSamples = 7200;
// Not a multiple of the 100-s window: the last partial block must be dropped.
constexpr Eigen::Index kVerSamples = 7250;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

bool HaveDygraphs() {
  try {
    html::LoadDygraphs();
    return true;
  } catch (const IoError&) {
    return false;
  }
}

// With `zero_truth` the truth column is all zeros (a gyro without thermal drift to remove).
void WriteLog(const std::string& path, const char* programme, double duration_s,
              std::uint64_t seed, bool zero_truth = false) {
  sim::SimulationOptions so;
  so.duration_s = duration_s;
  so.seed = seed;
  const sim::SimulationResult r = sim::Simulate(
      sim::BuiltinProgramme(programme), sim::PresetParameters(sim::Preset::kNavigation), so);
  io::WriteCsv(path, {{"time_s", r.time_s},
                      {"gyro", r.rate_dph},
                      {"temp", r.temperature_c},
                      {"drift", zero_truth ? Eigen::VectorXd::Zero(r.drift_dph.size()).eval()
                                           : r.drift_dph}});
}

double RmsAboutMean(const Eigen::VectorXd& v) {
  return std::sqrt((v.array() - v.mean()).square().mean());
}

double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / v.size()); }

// The cells of fleet.csv's column `name` in `row`.
const std::string& Cell(const FleetRow& row, const std::string& name) {
  const auto& columns = FleetColumns();
  const auto i =
      static_cast<size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
  EXPECT_LT(i, columns.size()) << name;
  return row.cells.at(i);
}

class FleetCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("fleet_calibration"));
    for (int i = 1; i <= 3; ++i) {
      const std::string sn = "SN" + std::to_string(i);
      WriteLog(Dir() + "/" + sn + "_cal.csv", "chamber", kCalSamples, 10 + i);
      // The same programme, another noise and turn-on bias: the first 2 h of chamber-b reach
      // histories a 2-h calibration (heating only) does not identify on some seeds, and the
      // model's quality is drift_fit_test's subject, not this file's.
      WriteLog(Dir() + "/" + sn + "_ver.csv", "chamber", kVerSamples, 20 + i);
    }
    WriteLog(Dir() + "/SNZ_ver.csv", "chamber", kVerSamples, 24, /*zero_truth=*/true);
    // SN1's verification log with a NaN gyro reading on its second data row.
    std::string text = io::ReadTextFile(Dir() + "/SN1_ver.csv");
    const size_t row = text.find('\n', text.find('\n') + 1) + 1;
    const size_t first = text.find(',', row) + 1;
    text.replace(first, text.find(',', first) - first, "nan");
    io::WriteFileAtomically(Dir() + "/SNX_ver.csv", text);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }

  struct Unit {
    std::string serial, calibration, verification;  // log names in Dir()
  };
  // A manifest of `limits` (lines of a [limits] table) and `units`.
  static Manifest Make(const std::string& limits, const std::vector<Unit>& units) {
    // Referenced to equilibrium at 20 degC, where the simulator's true drift is zero: its turn-on
    // bias, drawn anew for each run, is not in the truth column (docs/drift.md 1.3).
    std::string text = "rate_unit = \"dph\"\ndrift_window_s = 100\nreference_temperature_c = 20\n";
    if (!limits.empty()) text += "[limits]\n" + limits;
    text += "[[axis]]\ntarget = \"gyro\"\ntemperature = \"temp\"\ntruth = \"drift\"\n";
    for (const Unit& u : units) {
      text += "[[unit]]\nserial = \"" + u.serial + "\"\ncalibration = \"" + u.calibration +
              "\"\nverification = \"" + u.verification + "\"\n";
    }
    return ParseManifest(text, Dir() + "/fleet.toml");
  }
  static Unit Good(const std::string& serial) {
    return {serial, serial + "_cal.csv", serial + "_ver.csv"};
  }
  static Manifest Fleet(const std::string& limits = "") {
    return Make(limits, {Good("SN1"), Good("SN2"), Good("SN3")});
  }

  static std::string* dir_;
};
std::string* FleetCalibration::dir_ = nullptr;

TEST_F(FleetCalibration, AVerificationIsMeasuredAsDocumented) {
  const Manifest m = Fleet();
  const UnitOutputs out = CalibrateUnit(m, m.units[0], test::FakeDygraphs());
  const UnitResult& r = out.result;
  ASSERT_EQ(r.error, "");
  EXPECT_EQ(r.serial, "SN1");
  ASSERT_EQ(r.axes.size(), 1u);
  const AxisResult& a = r.axes[0];
  EXPECT_EQ(a.target, "gyro");
  EXPECT_EQ(a.temperature, "temp");
  EXPECT_EQ(a.model_summary.rfind("thermal", 0), 0u) << a.model_summary;
  EXPECT_FALSE(a.regressors.empty());
  EXPECT_TRUE(std::isfinite(a.bias));
  ASSERT_EQ(a.verification.size(), 1u);
  const VerificationResult& v = a.verification[0];

  std::vector<std::string> names;
  for (const auto& [name, text] : out.files) names.push_back(name);
  EXPECT_EQ(names, (std::vector<std::string>{"model.json", "verification_1_compensated.csv",
                                             "allan.csv", "report.html"}));
  // The compensated log: the verification log's columns, then the estimate, its standard
  // deviation and the compensated output.
  const io::CsvTable log = io::CsvTable::Read(Dir() + "/SN1_ver.csv");
  const io::CsvTable comp = io::CsvTable::Parse(out.files[1].second, "compensated");
  EXPECT_EQ(comp.header(), (std::vector<std::string>{"time_s", "gyro", "temp", "drift", "drift_est",
                                                     "drift_sd", "compensated"}));
  const Eigen::VectorXd y = log.Column("gyro"), truth = log.Column("drift");
  const Eigen::VectorXd estimate = comp.Column("drift_est");
  const Eigen::VectorXd compensated = comp.Column("compensated");
  EXPECT_EQ(comp.Column("gyro"), y);
  EXPECT_EQ(compensated, Eigen::VectorXd(y - estimate));
  // The estimate is the saved model's.
  const auto models = io::ParseModelFileAxes(out.files[0].second, "model.json");
  ASSERT_EQ(models.size(), 1u);
  EXPECT_EQ(estimate, drift::EstimateDrift(models[0].model, log.Column("temp")));

  EXPECT_EQ(v.log, "SN1_ver.csv");  // from the manifest's folder, as fleet.csv names it
  EXPECT_EQ(v.samples, kVerSamples);
  EXPECT_EQ(v.rate_hz, 1.0);
  EXPECT_DOUBLE_EQ(v.std_before, RmsAboutMean(y));
  EXPECT_DOUBLE_EQ(v.std_after, RmsAboutMean(compensated));
  EXPECT_DOUBLE_EQ(v.mean_before, y.mean());
  EXPECT_DOUBLE_EQ(v.mean_after, compensated.mean());
  // The calibration warnings decide whether the model counts as identified.
  ASSERT_TRUE(a.identified.has_value());
  EXPECT_EQ(*a.identified, a.warnings.empty()) << a.warnings.size();
  // 100-s block means: 72 whole blocks, the last 50 samples dropped.
  ASSERT_EQ(v.output_means.size(), kVerSamples / 100);
  Eigen::VectorXd means(kVerSamples / 100), comp_means(kVerSamples / 100);
  for (Eigen::Index b = 0; b < means.size(); ++b) {
    means[b] = y.segment(100 * b, 100).mean();
    comp_means[b] = compensated.segment(100 * b, 100).mean();
    EXPECT_DOUBLE_EQ(v.block_hours[b], (b + 0.5) * 100.0 / 3600.0);
  }
  for (Eigen::Index b = 0; b < means.size(); ++b) {
    EXPECT_DOUBLE_EQ(v.output_means[b], means[b]) << b;
    EXPECT_DOUBLE_EQ(v.compensated_means[b], comp_means[b]) << b;
  }
  EXPECT_EQ(v.truth_means.size(), means.size());
  EXPECT_DOUBLE_EQ(v.drift_rms_before, RmsAboutMean(means));
  EXPECT_DOUBLE_EQ(v.drift_rms_after, RmsAboutMean(comp_means));
  EXPECT_DOUBLE_EQ(v.truth_removed, 1.0 - Rms(truth - estimate) / Rms(truth));
  EXPECT_GE(v.outside_share, 0.0);
  EXPECT_LE(v.outside_share, 1.0);
  // The identified model does its job on this unit: less slow drift, most of the truth removed.
  EXPECT_LT(v.drift_rms_after, 0.5 * v.drift_rms_before);
  EXPECT_GT(v.truth_removed, 0.5);
  EXPECT_TRUE(v.failures.empty());  // no limits

  // allan.csv: the octave taus, and the deviation before and after, per axis and log.
  const io::CsvTable allan = io::CsvTable::Parse(out.files[2].second, "allan");
  EXPECT_EQ(allan.header(),
            (std::vector<std::string>{"tau_s_v1", "adev_before_gyro_v1", "adev_after_gyro_v1"}));
  EXPECT_EQ(allan.Column("tau_s_v1"), v.tau_s);
  EXPECT_EQ(allan.Column("adev_before_gyro_v1"), v.adev_before);
  EXPECT_EQ(allan.Column("adev_after_gyro_v1"), v.adev_after);
  EXPECT_GE(v.tau_s.size(), 8);
  EXPECT_EQ(v.tau_s[0], 1.0);
  for (Eigen::Index i = 1; i < v.tau_s.size(); ++i) EXPECT_EQ(v.tau_s[i], 2.0 * v.tau_s[i - 1]);
  EXPECT_TRUE(test::CheckReportHtml(out.files[3].second).ok());
}

TEST_F(FleetCalibration, LimitsFailStrictlyBeyondTheirValue) {
  const Manifest none = Fleet();
  const VerificationResult v =
      CalibrateUnit(none, none.units[1], test::FakeDygraphs()).result.axes.at(0).verification.at(0);
  // At the limit: pass (the limits are bounds the output may reach).
  const std::string at = "residual_drift_rms = " + io::FormatDouble(v.drift_rms_after) +
                         "\nremoved_share_min = " + io::FormatDouble(v.truth_removed) + "\n";
  const Manifest m_at = Fleet(at);
  const UnitResult pass = CalibrateUnit(m_at, m_at.units[1], test::FakeDygraphs()).result;
  ASSERT_EQ(pass.error, "");
  EXPECT_TRUE(pass.axes[0].verification[0].failures.empty());
  EXPECT_TRUE(pass.pass());
  // One step beyond each: both broken, each named with its value and limit.
  const std::string beyond =
      "residual_drift_rms = " + io::FormatDouble(std::nextafter(v.drift_rms_after, 0.0)) +
      "\nremoved_share_min = " + io::FormatDouble(std::nextafter(v.truth_removed, 1.0)) + "\n";
  const Manifest m_beyond = Fleet(beyond);
  const UnitResult fail = CalibrateUnit(m_beyond, m_beyond.units[1], test::FakeDygraphs()).result;
  ASSERT_EQ(fail.error, "");
  const std::vector<std::string>& failures = fail.axes[0].verification[0].failures;
  ASSERT_EQ(failures.size(), 2u);
  EXPECT_EQ(failures[0].rfind("residual drift ", 0), 0u) << failures[0];
  EXPECT_EQ(failures[1].rfind("removed ", 0), 0u) << failures[1];
  EXPECT_FALSE(fail.axes[0].pass());
  EXPECT_FALSE(fail.pass());
  const std::vector<FleetRow> rows = Rows(fail);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(Cell(rows[0], "status"), "fail");
  EXPECT_EQ(Cell(rows[0], "failures"), failures[0] + "; " + failures[1]);
  // The figures do not depend on the limits.
  EXPECT_EQ(fail.axes[0].verification[0].drift_rms_after, v.drift_rms_after);
}

TEST_F(FleetCalibration, ALimitIsNeverPassedOnAFigureThatWasNotMeasured) {
  const Manifest none = Fleet();
  const VerificationResult v =
      CalibrateUnit(none, none.units[1], test::FakeDygraphs()).result.axes.at(0).verification.at(0);
  // Bias instability: the fitted B when identified, else its bound, the flat bottom / 0.664 (the
  // 0 reported for an unidentified term must not pass any limit below that bound).
  const allan::NoiseTerm& b = v.noise_after.b_dph;
  const double figure = b.identified ? b.value : b.slope_reading;
  ASSERT_TRUE(std::isfinite(figure));
  ASSERT_GT(figure, 0.0);
  const Manifest m_at = Fleet("bias_instability_dph = " + io::FormatDouble(figure) + "\n");
  EXPECT_TRUE(CalibrateUnit(m_at, m_at.units[1], test::FakeDygraphs()).result.pass());
  const Manifest m_below =
      Fleet("bias_instability_dph = " + io::FormatDouble(std::nextafter(figure, 0.0)) + "\n");
  const UnitResult below = CalibrateUnit(m_below, m_below.units[1], test::FakeDygraphs()).result;
  ASSERT_EQ(below.error, "");
  ASSERT_EQ(below.axes[0].verification[0].failures.size(), 1u);
  const std::string& phrase = below.axes[0].verification[0].failures[0];
  EXPECT_EQ(phrase.rfind("bias instability ", 0), 0u) << phrase;
  EXPECT_EQ(phrase.find("not identified") != std::string::npos, !b.identified) << phrase;

  // A truth column of zeros leaves the removed share undefined: a set limit is broken, named so.
  const Manifest zero = Make("removed_share_min = 0\n", {{"SNZ", "SN2_cal.csv", "SNZ_ver.csv"}});
  const UnitResult z = CalibrateUnit(zero, zero.units[0], test::FakeDygraphs()).result;
  ASSERT_EQ(z.error, "");
  EXPECT_TRUE(std::isnan(z.axes[0].verification[0].truth_removed));
  ASSERT_EQ(z.axes[0].verification[0].failures.size(), 1u);
  EXPECT_EQ(z.axes[0].verification[0].failures[0],
            "removed share undefined (the true drift is zero)");
  EXPECT_FALSE(z.pass());
  // Without the limit the same log passes: only a set limit needs its figure.
  const Manifest zero_free = Make("", {{"SNZ", "SN2_cal.csv", "SNZ_ver.csv"}});
  EXPECT_TRUE(CalibrateUnit(zero_free, zero_free.units[0], test::FakeDygraphs()).result.pass());

  // A verification log shorter than two drift_window_s blocks has no residual drift to measure:
  // an empty cell, and a set limit broken, named so.
  Manifest long_window = Fleet("residual_drift_rms = 1e6\n");
  long_window.drift_window_s = static_cast<double>(kVerSamples);
  const UnitResult w =
      CalibrateUnit(long_window, long_window.units[1], test::FakeDygraphs()).result;
  ASSERT_EQ(w.error, "");
  EXPECT_TRUE(std::isnan(w.axes[0].verification[0].drift_rms_after));
  ASSERT_EQ(w.axes[0].verification[0].failures.size(), 1u);
  EXPECT_EQ(w.axes[0].verification[0].failures[0],
            "residual drift not measured (the log is shorter than two drift_window_s blocks)");
  EXPECT_EQ(Cell(Rows(w).at(0), "drift_rms_after"), "");
}

TEST_F(FleetCalibration, AUnitsOwnErrorIsItsResultNotAnException) {
  const Manifest m = Make("", {{"SNX", "SN1_cal.csv", "SNX_ver.csv"}});
  UnitOutputs out;
  ASSERT_NO_THROW(out = CalibrateUnit(m, m.units[0], test::FakeDygraphs()));
  EXPECT_EQ(out.result.serial, "SNX");
  EXPECT_NE(out.result.error.find("SNX_ver.csv"), std::string::npos) << out.result.error;
  EXPECT_EQ(out.result.error.find('\n'), std::string::npos) << out.result.error;
  EXPECT_TRUE(out.files.empty());
  EXPECT_FALSE(out.result.pass());
  const std::vector<FleetRow> rows = Rows(out.result);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(Cell(rows[0], "serial"), "SNX");
  EXPECT_EQ(Cell(rows[0], "status"), "error");
  EXPECT_EQ(Cell(rows[0], "failures"), out.result.error);
  EXPECT_EQ(Cell(rows[0], "axis"), "");
}

TEST(Rows, EveryCellComesFromTheResult) {
  UnitResult u;
  u.serial = "SN7";
  u.seconds = 0.25;
  AxisResult a;
  a.target = "gyro_x";
  a.model_summary = "thermal (compensate): 1 sub-model [signal], identified";
  a.regressors = {"T", "dT/dt"};
  a.bias = 0.125;
  a.cv_rmse = 0.0625;
  a.skill = 0.875;
  a.autopilot_kept = 0.5;
  a.warnings = {"no dwell", "narrow span"};
  a.identified = false;
  VerificationResult v;
  v.log = "logs/SN7_ver.csv";  // its path from the manifest's folder
  v.samples = 1234;
  v.mean_before = 1.5;
  v.mean_after = -0.125;
  v.std_before = 0.5;
  v.std_after = 0.25;
  v.drift_rms_before = 0.2;
  v.drift_rms_after = 0.05;
  v.truth_removed = kNan;  // no truth column
  v.outside_share = 0.1;
  v.noise_before.n_dpsh.value = 0.004;
  v.noise_after.n_dpsh.value = 0.003;
  v.noise_before.b_dph.value = 0.02;
  v.noise_after.b_dph.value = 0.01;
  v.noise_before.k_dphpsh.value = 0.002;
  v.noise_after.k_dphpsh.value = 0.001;
  for (allan::NoiseTerms* t : {&v.noise_before, &v.noise_after}) {
    t->n_dpsh.identified = t->b_dph.identified = t->k_dphpsh.identified = true;
  }
  v.failures = {"residual drift 0.05 > 0.04"};
  a.verification = {v};
  u.axes = {a};

  const std::vector<FleetRow> rows = Rows(u);
  ASSERT_EQ(rows.size(), 1u);
  const FleetRow& row = rows[0];
  ASSERT_EQ(row.cells.size(), FleetColumns().size());
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"serial", "SN7"},
      {"axis", "gyro_x"},
      {"verification", "logs/SN7_ver.csv"},
      {"status", "fail"},
      {"failures", "residual drift 0.05 > 0.04"},
      {"outliers", ""},       // FinishFleet's to fill
      {"method", "thermal"},  // the summary's first word
      {"samples", "1234"},
      {"std_before", "0.5"},
      {"std_after", "0.25"},
      {"drift_rms_before", "0.2"},
      {"drift_rms_after", "0.05"},
      {"drift_removed", io::FormatDouble(1.0 - 0.05 / 0.2)},
      {"truth_removed", ""},  // not applicable: empty, not "nan"
      {"arw_before_dpsh", "0.004"},
      {"arw_after_dpsh", "0.003"},
      {"bias_instability_before_dph", "0.02"},
      {"bias_instability_after_dph", "0.01"},
      {"rrw_before_dphpsh", "0.002"},
      {"rrw_after_dphpsh", "0.001"},
      {"bias", "0.125"},
      {"cv_rmse", "0.0625"},
      {"skill", "0.875"},
      {"autopilot_kept", "0.5"},
      {"regressors", "T; dT/dt"},
      {"warnings", "no dwell; narrow span"},
      {"identified", "no"},  // the calibration run could not identify the model
      {"outside_share", "0.1"},
      {"mean_before", "1.5"},
      {"mean_after", "-0.125"},
      {"unit_seconds", "0.25"}};
  ASSERT_EQ(expected.size(), FleetColumns().size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(FleetColumns()[i], expected[i].first);
    EXPECT_EQ(row.cells[i], expected[i].second) << expected[i].first;
  }
  // A noise term the fit did not identify is empty, not its 0 (nor in the outliers' statistics).
  u.axes[0].verification[0].noise_after.b_dph = allan::NoiseTerm{};
  EXPECT_EQ(Cell(Rows(u).at(0), "bias_instability_after_dph"), "");
  u.axes[0].verification[0].noise_after.b_dph = v.noise_after.b_dph;
  // No drift before: the share removed is not applicable rather than a division by zero.
  u.axes[0].verification[0].drift_rms_before = 0.0;
  u.axes[0].verification[0].failures.clear();
  const FleetRow flat = Rows(u).at(0);
  EXPECT_EQ(Cell(flat, "drift_removed"), "");
  EXPECT_EQ(Cell(flat, "status"), "pass");
  // One row per axis and verification log, in order.
  u.axes.push_back(u.axes[0]);
  u.axes[1].target = "gyro_y";
  u.axes[1].verification.push_back(u.axes[1].verification[0]);
  u.axes[1].verification[1].log = "second.csv";
  const std::vector<FleetRow> three = Rows(u);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(Cell(three[1], "axis"), "gyro_y");
  EXPECT_EQ(Cell(three[2], "verification"), "second.csv");
}

TEST_F(FleetCalibration, AFailingUnitIsReportedAndTheOthersGoOn) {
  const std::string out = Dir() + "/out_error";
  const Manifest m = Make("", {Good("SN2"), {"SNX", "SN1_cal.csv", "SNX_ver.csv"}, Good("SN3")});
  std::vector<UnitRun> runs;
  for (const UnitSpec& unit : m.units) {
    runs.push_back(RunUnit(m, unit, out, /*force=*/false, test::FakeDygraphs()));
  }
  EXPECT_EQ(runs[0].what, "calibrated");
  EXPECT_EQ(runs[1].what, "error");
  EXPECT_EQ(runs[2].what, "calibrated");
  EXPECT_LT(runs[1].seconds, 0.0);
  EXPECT_GE(runs[0].seconds, 0.0);
  EXPECT_TRUE(test::FileExists(out + "/SN2/summary.json"));
  EXPECT_TRUE(test::FileExists(out + "/SN3/summary.json"));
  EXPECT_FALSE(test::FileExists(out + "/SNX"));  // nothing of a failed unit

  const FleetResult fleet = FinishFleet(m, out, runs, 1.5, test::FakeDygraphs());
  EXPECT_EQ(fleet.units, 3);
  EXPECT_EQ(fleet.calibrated, 2);
  EXPECT_EQ(fleet.skipped, 0);
  EXPECT_EQ(fleet.errors, 1);
  EXPECT_EQ(fleet.failed_limits, 0);
  EXPECT_FALSE(fleet.all_pass());
  EXPECT_EQ(fleet.seconds, 1.5);
  ASSERT_EQ(fleet.rows.size(), 3u);  // manifest order
  EXPECT_EQ(fleet.rows[0].cells[0], "SN2");
  EXPECT_EQ(Cell(fleet.rows[1], "status"), "error");
  EXPECT_EQ(Cell(fleet.rows[2], "status"), "pass");
  // fleet.csv: the header, then every row (the error's message may hold commas: not parsed).
  const std::string csv = io::ReadTextFile(out + "/fleet.csv");
  std::string header;
  for (const std::string& c : FleetColumns()) header += (header.empty() ? "" : ",") + c;
  EXPECT_EQ(csv.rfind(header + "\n", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;
  EXPECT_NE(csv.find("\nSNX,,,error,"), std::string::npos) << csv;
  EXPECT_TRUE(test::CheckReportHtml(io::ReadTextFile(out + "/fleet.html")).ok());
}

// A unit that becomes an error loses what an earlier run wrote for it (a model and a page from
// logs the manifest no longer names, which its error row would contradict); a file of the user's
// in its folder stays.
TEST_F(FleetCalibration, AUnitThatBecomesAnErrorLosesItsEarlierResults) {
  const std::string out = Dir() + "/out_retract";
  const Manifest good = Make("", {{"SNR", "SN1_cal.csv", "SN1_ver.csv"}});
  ASSERT_EQ(RunUnit(good, good.units[0], out, false, test::FakeDygraphs()).what, "calibrated");
  // The model names its logs as the manifest does, whatever folder the run starts from.
  EXPECT_NE(io::ReadTextFile(out + "/SNR/model.json").find("\"source\": \"SN1_cal.csv\""),
            std::string::npos);
  const Manifest bad = Make("", {{"SNR", "SN1_cal.csv", "SNX_ver.csv"}});
  EXPECT_EQ(RunUnit(bad, bad.units[0], out, false, test::FakeDygraphs()).what, "error");
  EXPECT_FALSE(test::FileExists(out + "/SNR"));
  // Again, with a note of the user's in the folder: the unit's files go, the note stays.
  ASSERT_EQ(RunUnit(good, good.units[0], out, false, test::FakeDygraphs()).what, "calibrated");
  io::WriteFileAtomically(out + "/SNR/notes.txt", "checked by hand\n");
  EXPECT_EQ(RunUnit(bad, bad.units[0], out, false, test::FakeDygraphs()).what, "error");
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(out + "/SNR")) {
    left.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(left, std::vector<std::string>{"notes.txt"});
}

// A link left in a unit's folder never leads a write to the unit's own log: an error row, the log
// untouched (the writer would have replaced the file the link points to).
TEST_F(FleetCalibration, ALinkInTheOutputFolderNeverLeadsAWriteToAnInput) {
  const std::string out = Dir() + "/out_link";
  const Manifest m = Make("", {{"SNL", "SN1_cal.csv", "SN1_ver.csv"}});
  const std::string log = io::ReadTextFile(Dir() + "/SN1_cal.csv");
  fs::create_directories(out + "/SNL");
  fs::create_symlink(fs::absolute(Dir() + "/SN1_cal.csv"), out + "/SNL/report.html");
  const UnitRun run = RunUnit(m, m.units[0], out, false, test::FakeDygraphs());
  EXPECT_EQ(run.what, "error");
  ASSERT_FALSE(run.rows.empty());
  std::string cells;
  for (const std::string& c : run.rows[0].cells) cells += c + "|";
  EXPECT_NE(cells.find("is the input"), std::string::npos) << cells;
  EXPECT_EQ(io::ReadTextFile(Dir() + "/SN1_cal.csv"), log);
}

// A verification log that is a copy of the calibration log would judge the model on what it was
// fitted on: an error row, as for the same file named twice.
TEST_F(FleetCalibration, ACopyOfTheCalibrationLogIsNoVerification) {
  io::WriteFileAtomically(Dir() + "/SN1_copy.csv", io::ReadTextFile(Dir() + "/SN1_cal.csv"));
  const Manifest m = Make("", {{"SNC", "SN1_cal.csv", "SN1_copy.csv"}});
  const UnitOutputs out = CalibrateUnit(m, m.units[0], test::FakeDygraphs());
  EXPECT_NE(out.result.error.find("SN1_copy.csv holds the bytes of calibration log"),
            std::string::npos)
      << out.result.error;
}

TEST_F(FleetCalibration, AFinishedUnitIsSkippedAndADamagedOneRedone) {
  const std::string out = Dir() + "/out_rerun";
  const Manifest m = Make("", {Good("SN3")});
  const UnitRun first = RunUnit(m, m.units[0], out, false, test::FakeDygraphs());
  ASSERT_EQ(first.what, "calibrated");
  const std::string model = io::ReadTextFile(out + "/SN3/model.json");
  // Skipped: the rows come back from summary.json as they were written, timing included.
  const UnitRun again = RunUnit(m, m.units[0], out, false, test::FakeDygraphs());
  EXPECT_EQ(again.what, "skipped");
  EXPECT_LT(again.seconds, 0.0);
  ASSERT_EQ(again.rows.size(), first.rows.size());
  EXPECT_EQ(again.rows[0].cells, first.rows[0].cells);
  // Another limit changes the fingerprint: redone.
  const Manifest limited = Make("residual_drift_rms = 1\n", {Good("SN3")});
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what, "calibrated");
  // A damaged summary is not trusted.
  const std::string summary = io::ReadTextFile(out + "/SN3/summary.json");
  io::WriteFileAtomically(out + "/SN3/summary.json", summary.substr(0, summary.size() / 2));
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what, "calibrated");
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what, "skipped");
  // Forced: redone, to the same model.
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, true, test::FakeDygraphs()).what, "calibrated");
  EXPECT_EQ(io::ReadTextFile(out + "/SN3/model.json"), model);
  // A file deleted or edited since it was written: redone, never skipped over.
  fs::remove(out + "/SN3/model.json");
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what,
            "calibrated");
  EXPECT_EQ(io::ReadTextFile(out + "/SN3/model.json"), model);
  io::WriteFileAtomically(out + "/SN3/report.html", "garbage");
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what,
            "calibrated");
  EXPECT_NE(io::ReadTextFile(out + "/SN3/report.html"), "garbage");
  EXPECT_EQ(RunUnit(limited, limited.units[0], out, false, test::FakeDygraphs()).what, "skipped");
}

// Rows by hand for FinishFleet: unit i on axis "gyro" with the given residual drift after.
UnitRun HandMadeRun(const std::string& serial, const std::string& status, double drift_after,
                    double seconds, const std::string& what = "calibrated") {
  FleetRow row;
  row.cells.assign(FleetColumns().size(), "");
  row.cells[0] = serial;
  const auto set = [&](const std::string& name, const std::string& value) {
    const auto& c = FleetColumns();
    row.cells[static_cast<size_t>(std::find(c.begin(), c.end(), name) - c.begin())] = value;
  };
  set("status", status);
  if (status != "error") {
    set("axis", "gyro");
    set("verification", serial + "_ver.csv");
    set("drift_rms_after", io::FormatDouble(drift_after));
    set("bias", "0.5");
  } else {
    set("failures", "log.csv: data row 2 is 'nan', \"quoted\"");
  }
  return UnitRun{{row}, what, what == "calibrated" ? seconds : -1.0};
}

TEST(FinishFleet, CountsFlagsOutliersAndWritesTheTable) {
  const std::string dir = test::TempDir("fleet_finish");
  Manifest m;
  m.axes = {AxisSpec{.target = "gyro", .temperature = {"temp"}}};
  m.units.resize(7);
  // Six units on one axis (the modified z-score needs at least five) and one error. Median of
  // the six: 1.025; MAD: 0.075, so 1.4826 MAD = 0.1112: 10 lies 80 of them away, 1.1 only 0.67.
  const std::vector<UnitRun> runs = {
      HandMadeRun("A", "pass", 1.0, 2.0),          HandMadeRun("B", "pass", 1.1, 3.0),
      HandMadeRun("C", "fail", 0.9, 4.0),          HandMadeRun("D", "pass", 1.05, 0.0, "skipped"),
      HandMadeRun("E", "pass", 0.95, 5.0),         HandMadeRun("F", "fail", 10.0, 6.0),
      HandMadeRun("G", "error", 0.0, 0.0, "error")};
  const FleetResult fleet = FinishFleet(m, dir, runs, 9.0, test::FakeDygraphs());
  EXPECT_EQ(fleet.units, 7);
  EXPECT_EQ(fleet.calibrated, 5);
  EXPECT_EQ(fleet.skipped, 1);
  EXPECT_EQ(fleet.errors, 1);
  EXPECT_EQ(fleet.failed_limits, 2);
  EXPECT_EQ(fleet.unit_seconds_median, 4.0);  // of the calibrated units' 2, 3, 4, 5, 6
  ASSERT_EQ(fleet.rows.size(), 7u);
  for (size_t i = 0; i < fleet.rows.size(); ++i) {
    // The bias is the same everywhere (MAD 0): nothing is flagged for it.
    EXPECT_EQ(Cell(fleet.rows[i], "outliers"), i == 5 ? "drift_rms_after" : "") << i;
  }
  // The summary line holds the counts.
  EXPECT_NE(fleet.Summary().find("7 units: 5 calibrated, 1 skipped (done before), 2 failed their "
                                 "limits, 1 could not be calibrated"),
            std::string::npos)
      << fleet.Summary();
  // A rerun that calibrated nothing has no time per unit to give (it printed "nan s" before).
  FleetResult rerun;
  rerun.units = rerun.skipped = 3;
  rerun.seconds = 0.5;
  rerun.unit_seconds_median = std::nan("");
  EXPECT_EQ(rerun.Summary(),
            "3 units: 0 calibrated, 3 skipped (done before), 0 failed their limits, 0 could not be "
            "calibrated; 0.5 s");

  // fleet.csv: a cell with a comma or a quote is quoted, its quotes doubled.
  const std::string csv = io::ReadTextFile(dir + "/fleet.csv");
  std::string header;
  for (const std::string& c : FleetColumns()) header += (header.empty() ? "" : ",") + c;
  EXPECT_EQ(csv.rfind(header + "\n", 0), 0u);
  EXPECT_NE(csv.find("\nG,,,error,\"log.csv: data row 2 is 'nan', \"\"quoted\"\"\","),
            std::string::npos)
      << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 8);
  EXPECT_TRUE(test::FileExists(dir + "/fleet.html"));

  // Five units: still enough to flag; four: too few to call one unusual.
  std::vector<UnitRun> five(runs.begin() + 1, runs.begin() + 6);
  m.units.resize(5);
  EXPECT_EQ(Cell(FinishFleet(m, dir, five, 1.0, test::FakeDygraphs()).rows[4], "outliers"),
            "drift_rms_after");
  std::vector<UnitRun> four(runs.begin() + 2, runs.begin() + 6);
  m.units.resize(4);
  for (const FleetRow& row : FinishFleet(m, dir, four, 1.0, test::FakeDygraphs()).rows) {
    EXPECT_EQ(Cell(row, "outliers"), "");
  }
  // One run per unit of the manifest, or a UsageError.
  EXPECT_THROW(FinishFleet(m, dir, five, 1.0, test::FakeDygraphs()), UsageError);
}

TEST(FinishFleet, OutliersNeedFiveUnitsNotFiveRows) {
  // Regression: the threshold counted rows, so four units with two verification logs each (eight
  // rows) had a unit flagged although docs/calibration.md asks for at least 5 units.
  const std::string dir = test::TempDir("fleet_outlier_units");
  Manifest m;
  m.axes = {AxisSpec{.target = "gyro", .temperature = {"temp"}}};
  const std::vector<double> drift = {1.0, 1.1, 0.9, 10.0};
  std::vector<UnitRun> runs;
  for (size_t u = 0; u < drift.size(); ++u) {
    UnitRun run = HandMadeRun(std::string(1, static_cast<char>('A' + u)), "pass", drift[u], 1.0);
    run.rows.push_back(run.rows[0]);
    run.rows[1].cells[2] = "second_ver.csv";
    runs.push_back(run);
  }
  m.units.resize(runs.size());
  for (const FleetRow& row : FinishFleet(m, dir, runs, 1.0, test::FakeDygraphs()).rows) {
    EXPECT_EQ(Cell(row, "outliers"), "") << row.cells[0];
  }
  // A fifth unit: now the odd one is flagged, on both of its rows.
  runs.push_back(HandMadeRun("E", "pass", 0.95, 1.0));
  m.units.resize(runs.size());
  const FleetResult five = FinishFleet(m, dir, runs, 1.0, test::FakeDygraphs());
  for (const FleetRow& row : five.rows) {
    EXPECT_EQ(Cell(row, "outliers"), row.cells[0] == "D" ? "drift_rms_after" : "") << row.cells[0];
  }
}

TEST_F(FleetCalibration, ResultsDoNotDependOnTheThreadCount) {
  if (!HaveDygraphs()) GTEST_SKIP() << "libjs-dygraphs not installed";
  const Manifest m = Fleet();
  std::vector<FleetResult> results;
  for (int threads : {1, 2}) {
    std::vector<std::string> serials;
    std::vector<int> done;
    FleetContext context{
        .threads = threads,
        .progress = [&](int d, int total, const std::string& serial, const std::string& what) {
          EXPECT_EQ(total, 3);
          EXPECT_EQ(what, "calibrated");
          done.push_back(d);
          serials.push_back(serial);
        }};
    results.push_back(
        RunFleet(m, {.output_dir = Dir() + "/out_threads" + std::to_string(threads)}, context));
    EXPECT_EQ(done, (std::vector<int>{1, 2, 3}));
    std::sort(serials.begin(), serials.end());
    EXPECT_EQ(serials, (std::vector<std::string>{"SN1", "SN2", "SN3"}));
  }
  EXPECT_EQ(results[0].calibrated, 3);
  EXPECT_TRUE(results[0].all_pass());
  ASSERT_EQ(results[0].rows.size(), results[1].rows.size());
  for (size_t i = 0; i < results[0].rows.size(); ++i) {
    std::vector<std::string> a = results[0].rows[i].cells, b = results[1].rows[i].cells;
    a.pop_back();  // unit_seconds: the only timing
    b.pop_back();
    EXPECT_EQ(a, b) << i;
  }
  for (const char* sn : {"SN1", "SN2", "SN3"}) {
    for (const char* file :
         {"model.json", "verification_1_compensated.csv", "allan.csv", "report.html"}) {
      EXPECT_EQ(io::ReadTextFile(Dir() + "/out_threads1/" + sn + "/" + file),
                io::ReadTextFile(Dir() + "/out_threads2/" + sn + "/" + file))
          << sn << "/" << file;
    }
  }
}

TEST_F(FleetCalibration, RunFleetRefusesWhatIsNotAUnitsOwnProblem) {
  const Manifest m = Fleet();
  const std::string out = Dir() + "/out_refused";
  EXPECT_THROW(RunFleet(m, {.output_dir = out}, {.threads = -1}), OptionError);
  EXPECT_THROW(RunFleet(m, {.output_dir = out}, {.threads = 1025}), OptionError);
  EXPECT_FALSE(fs::exists(out));  // refused before the folder is made
  io::WriteFileAtomically(out, "a file");
  EXPECT_THROW(RunFleet(m, {.output_dir = out + "/sub"}), IoError);
  // An output folder that holds the manifest's logs: refused before anything is written, by the
  // fleet and by a unit's run alone (the Python package's Dask tasks), whatever the front end.
  const std::string holder = fs::path(m.units[0].calibration[0]).parent_path().string();
  const auto listing = [&] {
    std::vector<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(holder)) names.push_back(e.path());
    std::sort(names.begin(), names.end());
    return names;
  };
  const std::vector<std::string> before = listing();
  EXPECT_THROW(RunFleet(m, {.output_dir = holder}), UsageError);
  EXPECT_THROW(RunUnit(m, m.units[0], holder, false, test::FakeDygraphs()), UsageError);
  EXPECT_EQ(listing(), before);
}

TEST_F(FleetCalibration, AProgressThatThrowsStopsTheFleet) {
  if (!HaveDygraphs()) GTEST_SKIP() << "libjs-dygraphs not installed";
  const Manifest m = Fleet();
  const std::string out = Dir() + "/out_stopped";
  struct Stop {};
  FleetContext context{
      .threads = 1,
      .progress = [](int, int, const std::string&, const std::string&) { throw Stop{}; }};
  EXPECT_THROW(RunFleet(m, {.output_dir = out}, context), Stop);
  // The unit already written stays; the fleet's table is not written.
  EXPECT_TRUE(test::FileExists(out + "/SN1/summary.json"));
  EXPECT_FALSE(test::FileExists(out + "/fleet.csv"));
}

}  // namespace
}  // namespace gyrodrift::fleet
