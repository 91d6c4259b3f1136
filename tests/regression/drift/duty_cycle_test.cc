// A duty-cycled calibration (issue 22, item 4): the logger keeps 5 s of every 300 s. Made here,
// in C++, from shipped family units' continuous 16-h calibrations (the rows of each burst kept,
// the rest dropped, as generate.py --bursts 5,300 does), read back with --gaps carry (filled on
// the time grid, the fill masked) and fitted with the defaults on the logged rows only. Without
// noise the carry fit reproduces the continuous fit's estimate; with it, it compensates the
// mission run better than interpolating the fill as data (the old way).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "../allan/allan_fixtures.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"
#include "support/test_support.h"

namespace gyrodrift::drift {
namespace {

io::CsvTable ReadUnitFile(const std::string& name) {
  return io::CsvTable::Read(
      allan::fixtures::Gunzip(test::TestDataPath("gyro_thermal_family/units/" + name), name));
}

double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / static_cast<double>(v.size())); }

double ShareRemovedPercent(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth) {
  return 100.0 * (1.0 - Rms(estimate - truth) / Rms(truth));
}

// The rows of `table` whose time_s lies in the first `on_s` of every `period_s`, as a CSV file.
std::string WriteBursts(const io::CsvTable& table, double on_s, double period_s,
                        const std::string& path) {
  const Eigen::VectorXd t = table.Column("time_s");
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    if (std::fmod(t[i] - t[0], period_s) < on_s) rows.push_back(i);
  }
  std::vector<io::CsvColumn> columns;
  for (const char* name : {"time_s", "rate_dph", "temperature_c"}) {
    const Eigen::VectorXd all = table.Column(name);
    Eigen::VectorXd kept(static_cast<Eigen::Index>(rows.size()));
    for (size_t k = 0; k < rows.size(); ++k) kept[static_cast<Eigen::Index>(k)] = all[rows[k]];
    columns.push_back({name, kept});
  }
  io::WriteCsv(path, columns);
  return path;
}

// The fit of a noise-free drift (the mission run's truth, as the calibration's output) from the
// bursts alone: what carry keeps of the continuous fit when the noise does not decide. The lag
// states must run across the gaps: split (every 5-s burst a record of its own) cannot identify them.
TEST(DutyCycledTruth, CarryKeepsTheThermalStatesOfTheContinuousFit) {
  const io::CsvTable mission = ReadUnitFile("unit1_test8h_mission.csv.gz");
  const io::CsvTable truth = ReadUnitFile("unit1_test8h_mission_truth.csv.gz");
  std::vector<io::CsvColumn> columns{{"time_s", mission.Column("time_s")},
                                     {"rate_dph", truth.Column("drift_dph")},
                                     {"temperature_c", mission.Column("temperature_c")}};
  const std::string dir = test::TempDir("duty_cycle");
  io::WriteCsv(dir + "/truth.csv", columns);
  const io::CsvTable full = io::CsvTable::Read(dir + "/truth.csv");
  const std::string bursts = WriteBursts(full, 5.0, 300.0, dir + "/truth_bursts.csv");
  std::vector<bool> logged;
  const io::CsvTable filled =
      io::ReadLog(bursts, {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
  std::vector<Eigen::Index> starts;
  const io::CsvTable split = io::ReadLog(bursts, {io::GapPolicy::kSplit}, nullptr, &starts);

  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kThermal;
  const Eigen::VectorXd t = full.Column("temperature_c");
  const Eigen::VectorXd reference =
      EstimateDrift(FitDriftModel(full.Column("rate_dph"), t, o), t);
  const DriftModel carry =
      FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"), o, {}, {}, logged);
  const DriftModel pieces =
      FitDriftModel(split.Column("rate_dph"), split.Column("temperature_c"), o, starts);
  const double scale = Rms(reference);
  const double carry_apart = 100.0 * Rms(EstimateDrift(carry, t) - reference) / scale;
  const double split_apart = 100.0 * Rms(EstimateDrift(pieces, t) - reference) / scale;
  std::printf("noise-free unit 1: carry %.1f %%, split %.1f %% of the continuous estimate apart\n",
              carry_apart, split_apart);
  // Measured: carry 2.4 % (0.4 % before the sparse-log ridge, docs/drift.md 4.8), split 37.5 %.
  EXPECT_LE(carry_apart, 3.0) << carry.Summary();
  EXPECT_GE(split_apart, 10.0) << pieces.Summary();
}

// With the gyro's noise, 960 logged samples of 57,600 decide the structure: measured (main 43053c3
// merged), unit 1: continuous 86.6 %, carry 76.5 %, interpolate -206.1 %; unit 2: continuous
// 83.6 %, carry -15.7 %, interpolate 48.7 % (not a floor: the structure chosen from the bursts
// extrapolates on the mission, an identification matter, docs/drift.md 4.6). The floor keeps
// unit 1's margin over interpolation.
TEST(DutyCycledUnit, CarryBeatsInterpolationOnUnit1) {
  const io::CsvTable train = ReadUnitFile("unit1_train16h.csv.gz");
  const io::CsvTable test = ReadUnitFile("unit1_test8h_mission.csv.gz");
  const Eigen::VectorXd truth = ReadUnitFile("unit1_test8h_mission_truth.csv.gz").Column("drift_dph");
  const Eigen::VectorXd mission_t = test.Column("temperature_c");
  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kThermal;
  const std::string bursts =
      WriteBursts(train, 5.0, 300.0, test::TempDir("duty_cycle") + "/unit1_bursts.csv");
  std::vector<bool> logged;
  const io::CsvTable filled =
      io::ReadLog(bursts, {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
  ASSERT_EQ(filled.rows(), train.rows() - 295);  // the last burst ends the log
  ASSERT_EQ(CountLogged(logged, filled.rows()), 192 * 5);
  const DriftModel carry =
      FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"), o, {}, {}, logged);
  const DriftModel interpolate =
      FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"), o);
  const double removed_carry = ShareRemovedPercent(EstimateDrift(carry, mission_t), truth);
  const double removed_interpolate =
      ShareRemovedPercent(EstimateDrift(interpolate, mission_t), truth);
  std::printf("unit 1: carry %.1f %%, interpolate %.1f %%\n", removed_carry, removed_interpolate);
  EXPECT_GE(removed_carry, 66.0) << carry.Summary();
  EXPECT_GT(removed_carry, removed_interpolate) << carry.Summary();
}

// Issue 22's floor on the duty-cycled calibrations of the shipped units 1-4 (16 h, 5 s of every
// 300 s, carry): none worse than not compensating. Measured: 80.7 / 35.1 / 92.7 / 71.0 %; unit 2
// removed -15.7 % before the sparse-log ridge and -12.5 % with it while the hysteresis term was
// tried on the log's 16-h span (its 960 logged samples are 16 min; docs/drift.md 4.8).
TEST(DutyCycledUnit, NoShippedUnitIsMadeWorse) {
  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kThermal;
  for (int unit = 1; unit <= 4; ++unit) {
    const std::string u = "unit" + std::to_string(unit);
    const io::CsvTable train = ReadUnitFile(u + "_train16h.csv.gz");
    const Eigen::VectorXd mission_t =
        ReadUnitFile(u + "_test8h_mission.csv.gz").Column("temperature_c");
    const Eigen::VectorXd truth =
        ReadUnitFile(u + "_test8h_mission_truth.csv.gz").Column("drift_dph");
    const std::string bursts =
        WriteBursts(train, 5.0, 300.0, test::TempDir("duty_cycle") + "/" + u + "_bursts.csv");
    std::vector<bool> logged;
    const io::CsvTable filled =
        io::ReadLog(bursts, {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
    const DriftModel carry =
        FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"), o, {}, {}, logged);
    const double removed = ShareRemovedPercent(EstimateDrift(carry, mission_t), truth);
    std::printf("%s: carry %.1f %%\n", u.c_str(), removed);
    EXPECT_GE(removed, 0.0) << u << ": " << carry.Summary();
  }
}

}  // namespace
}  // namespace gyrodrift::drift
