// A duty-cycled calibration (issue 22, item 4): the logger keeps 5 s of every 300 s. Made here,
// in C++, from shipped family units' continuous 16-h calibrations (the rows of each burst kept,
// the rest dropped, as generate.py --bursts 5,300 does), read back with --gaps carry (filled on
// the time grid, the fill masked), fitted with the defaults on the logged rows only, and used to
// compensate the unit's 8-h mission run. The carry fit must reproduce the continuous fit's drift
// estimate closely; interpolating the fill as data (the old way) is the comparison.
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

struct UnitCase {
  int unit;
  double max_gap_points;  // how far the carry fit's share may fall below the continuous fit's
};

class DutyCycledUnit : public ::testing::TestWithParam<UnitCase> {};

TEST_P(DutyCycledUnit, CarryReproducesTheContinuousCalibration) {
  const UnitCase c = GetParam();
  const std::string stem = "unit" + std::to_string(c.unit);
  const io::CsvTable train = ReadUnitFile(stem + "_train16h.csv.gz");
  const io::CsvTable test = ReadUnitFile(stem + "_test8h_mission.csv.gz");
  const Eigen::VectorXd truth = ReadUnitFile(stem + "_test8h_mission_truth.csv.gz").Column("drift_dph");
  const Eigen::VectorXd mission_t = test.Column("temperature_c");

  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kThermal;
  const DriftModel continuous =
      FitDriftModel(train.Column("rate_dph"), train.Column("temperature_c"), o);
  const Eigen::VectorXd reference = EstimateDrift(continuous, mission_t);

  const std::string bursts =
      WriteBursts(train, 5.0, 300.0, test::TempDir("duty_cycle") + "/" + stem + "_bursts.csv");
  std::vector<bool> logged;
  const io::CsvTable filled = io::ReadLog(bursts, {io::GapPolicy::kCarry}, nullptr, nullptr, {}, &logged);
  ASSERT_EQ(filled.rows(), train.rows() - 295);  // the last burst ends the log
  ASSERT_EQ(CountLogged(logged, filled.rows()), 192 * 5);
  const DriftModel carry = FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"),
                                         o, {}, {}, logged);
  const DriftModel interpolate =
      FitDriftModel(filled.Column("rate_dph"), filled.Column("temperature_c"), o);
  const Eigen::VectorXd carried = EstimateDrift(carry, mission_t);
  const double removed_continuous = ShareRemovedPercent(reference, truth);
  const double removed_carry = ShareRemovedPercent(carried, truth);
  const double removed_interpolate =
      ShareRemovedPercent(EstimateDrift(interpolate, mission_t), truth);
  // How far the carry estimate lies from the continuous one, as a share of the true drift.
  const double apart = 100.0 * Rms(carried - reference) / Rms(truth);
  std::printf("unit %d: continuous %.1f %%, carry %.1f %%, interpolate %.1f %%, carry vs "
              "continuous %.1f %% of the drift\n",
              c.unit, removed_continuous, removed_carry, removed_interpolate, apart);
  EXPECT_GE(removed_carry, 0.0) << carry.Summary();
  EXPECT_GE(removed_carry, removed_continuous - c.max_gap_points) << carry.Summary();
  EXPECT_LE(apart, c.max_gap_points) << carry.Summary();
}

INSTANTIATE_TEST_SUITE_P(Shipped, DutyCycledUnit,
                         ::testing::Values(UnitCase{1, 15.0}, UnitCase{2, 15.0}),
                         [](const auto& info) { return "unit" + std::to_string(info.param.unit); });

}  // namespace
}  // namespace gyrodrift::drift
