// Oracle: the maximal-overlap Allan variance that the R package avar computed on a real 2.8-hour
// ADIS16405 IMU record (1e6 samples at 100 Hz). Provenance, licence and tolerance:
// ../shared/testdata/smac_adis16405_avar/SOURCE.md. The gzip CSV is unpacked with the system
// gzip into the test's temp directory (no zlib dependency).
#include <gtest/gtest.h>

#include <map>

#include "allan_fixtures.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/io/csv.h"
#include "support/test_support.h"

namespace gyrodrift::allan {
namespace {

TEST(Adis16405, OverlappingAvarMatchesRPackageAvar) {
  const std::string raw = fixtures::Gunzip(
      test::TestDataPath("smac_adis16405_avar/adis_16405_imu1.csv.gz"), "allan-adis16405");
  const io::CsvTable table = io::CsvTable::Read(raw);
  ASSERT_EQ(table.rows(), 1000000);
  const io::CsvTable ref = io::CsvTable::Read(
      test::TestDataPath("smac_adis16405_avar/adis_16405_imu1_avar_mo_reference.csv"));
  // The channel column is text; read it from the raw file alongside the numeric columns.
  std::ifstream in(test::TestDataPath("smac_adis16405_avar/adis_16405_imu1_avar_mo_reference.csv"));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> channel;
  while (std::getline(in, line)) channel.push_back(line.substr(1, line.find('"', 1) - 1));
  ASSERT_EQ(static_cast<Eigen::Index>(channel.size()), ref.rows());
  const Eigen::VectorXd ref_tau = ref.Column("tau_s");
  const Eigen::VectorXd ref_avar = ref.Column("avar");
  const std::map<std::string, std::string> columns = {{"Gyro. X", "gyro_x"}, {"Gyro. Y", "gyro_y"},
                                                      {"Gyro. Z", "gyro_z"}, {"Accel. X", "acc_x"},
                                                      {"Accel. Y", "acc_y"}, {"Accel. Z", "acc_z"}};
  int checked = 0;
  double worst = 0.0;
  for (const auto& [name, column] : columns) {
    AllanOptions o{.rate_hz = 100.0,
                   .deviation = Deviation::kOadev,
                   .grid = TauGrid::kList,
                   .units = RateUnit::kDegPerSecond,
                   .confidence_intervals = false};
    std::vector<Eigen::Index> rows;
    for (Eigen::Index i = 0; i < ref.rows(); ++i) {
      if (channel[static_cast<size_t>(i)] != name) continue;
      rows.push_back(i);
      o.tau_list_s.push_back(ref_tau[i]);
    }
    ASSERT_EQ(rows.size(), 18u) << name;
    const AllanResult r = Compute(table.Column(column), o);
    ASSERT_EQ(r.points.size(), rows.size());
    for (size_t k = 0; k < rows.size(); ++k) {
      const double avar = r.points[k].dev * r.points[k].dev;
      const double rel = fixtures::RelErr(avar, ref_avar[rows[k]]);
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-5) << name << " tau " << r.points[k].tau_s;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 108);
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf("ADIS16405: %d reference points, worst relative AVAR error %.3g\n", checked, worst);
}

}  // namespace
}  // namespace gyrodrift::allan
