// A PX4 ULog given directly to fit, compensate and calibrate: the same numbers as its converted
// CSV (the model and the compensated log byte for byte), the instance chosen by --ulog-instance
// (the manifest's ulog_instance), the log untouched, and the CSV-only flags and a unit other than
// the ULog's refused.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"
#include "support/ulog_writer.h"

namespace gyrodrift {
namespace {

constexpr double kRadsPerDph = M_PI / 180.0 / 3600.0;

// A 40-min thermal log as a ULog: x the log's rate, y its opposite, z half of it.
std::string WriteLog(const std::string& dir, const std::string& name = "log", int seed = 11) {
  io::WriteFileAtomically(dir + "/" + name + ".csv", test::ThermalLogCsv(2400, seed));
  std::vector<std::string> header;
  const Eigen::MatrixXd m = test::ReadCsvMatrix(dir + "/" + name + ".csv", &header);
  EXPECT_EQ(header[1], "rate_dph");
  Eigen::MatrixXd xyz(m.rows(), 3);
  xyz << m.col(1) * kRadsPerDph, -m.col(1) * kRadsPerDph, 0.5 * m.col(1) * kRadsPerDph;
  test::WriteSensorGyroUlog(dir + "/" + name + ".ulg", m.col(0), xyz, m.col(2), 2490378, 1);
  return dir + "/" + name + ".ulg";
}

std::string Read(const std::string& path) { return io::ReadTextFile(path); }

TEST(UlogInputCli, FitAndCompensateReadAUlogAsItsConvertedCsv) {
  const std::string d = test::TempDir("cli_ulog_input");
  const std::string ulg = WriteLog(d);
  const std::string before = Read(ulg);
  const test::CommandResult convert =
      test::RunCli("convert '" + ulg + "' --instance 1 -q -o '" + d + "/conv.csv'");
  ASSERT_EQ(convert.exit_code, 0) << convert.err;
  const std::string fit = " -t x_dph,y_dph,z_dph -T temperature_c --mode compensate -q -o '";
  const test::CommandResult from_ulog =
      test::RunCli("fit '" + ulg + "' --ulog-instance 1" + fit + d + "/m_ulog.json'");
  ASSERT_EQ(from_ulog.exit_code, 0) << from_ulog.err;
  const test::CommandResult from_csv = test::RunCli("fit '" + d + "/conv.csv'" + fit + d +
                                                    "/m_csv.json'");
  ASSERT_EQ(from_csv.exit_code, 0) << from_csv.err;
  for (const char* model : {"m_ulog", "m_csv"}) {
    const test::CommandResult c = test::RunCli("compensate '" + d + "/" + std::string(model) + ".json' '" +
                                               ulg + "' --ulog-instance 1 -q -o '" + d + "/c_" +
                                               model + ".csv'");
    ASSERT_EQ(c.exit_code, 0) << c.err;
  }
  const test::CommandResult c = test::RunCli("compensate '" + d + "/m_csv.json' '" + d +
                                             "/conv.csv' -q -o '" + d + "/c_conv.csv'");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(Read(d + "/c_m_ulog.csv"), Read(d + "/c_m_csv.csv"));
  EXPECT_EQ(Read(d + "/c_m_csv.csv"), Read(d + "/c_conv.csv"));
  EXPECT_EQ(io::CsvTable::Read(d + "/c_conv.csv").rows(), 2400);
  EXPECT_EQ(Read(ulg), before);
}

// A fleet manifest names the ULog's instance as a key: calibrate fits the model fit writes, and
// its model exports to PX4's parameters.
TEST(UlogInputCli, CalibrateReadsAUlogAsFitDoes) {
  const std::string d = test::TempDir("cli_ulog_calibrate");
  const std::string ulg = WriteLog(d);
  std::string manifest = "ulog_instance = 1\n";
  for (const char* axis : {"x_dph", "y_dph", "z_dph"}) {
    manifest += std::string("[[axis]]\ntarget = \"") + axis + "\"\ntemperature = \"temperature_c\"\n";
  }
  // The verification another run (a copy of the calibration is refused: FitUnit).
  const std::string ver = WriteLog(d, "ver", 12);
  manifest +=
      "[[unit]]\nserial = \"IMU\"\ncalibration = \"" + ulg + "\"\nverification = \"" + ver + "\"\n";
  io::WriteFileAtomically(d + "/fleet.toml", manifest);
  const test::CommandResult cal =
      test::RunCli("calibrate '" + d + "/fleet.toml' -o '" + d + "/out' -q");
  ASSERT_EQ(cal.exit_code, 0) << cal.out << cal.err;
  const test::CommandResult fit =
      test::RunCli("fit '" + ulg + "' --ulog-instance 1 -t x_dph,y_dph,z_dph -T temperature_c "
                   "--mode compensate -q -o '" + d + "/fit.json'");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_EQ(io::ReadTextFile(d + "/out/IMU/model.json"), io::ReadTextFile(d + "/fit.json"));
  const test::CommandResult px4 =
      test::RunCli("export '" + d + "/out/IMU/model.json' --format px4 --device-id 2490378 -q -o '" +
                   d + "/tc.params'");
  ASSERT_EQ(px4.exit_code, 0) << px4.err;
  EXPECT_NE(io::ReadTextFile(d + "/tc.params").find("TC_G0_ID\t2490378\t6"), std::string::npos);
}

TEST(UlogInputCli, AMissingInstanceOrACsvFlagIsRefusedCleanly) {
  const std::string d = test::TempDir("cli_ulog_input_bad");
  const std::string ulg = WriteLog(d);
  const std::string out = d + "/m.json";
  const std::string fit = "fit '" + ulg + "' -t x_dph -T temperature_c --mode compensate -o '" +
                          out + "' ";
  test::ExpectCleanFailure(test::RunCli(fit), 3, "sensor_gyro", out, "instance 0 absent");
  test::ExpectCleanFailure(test::RunCli(fit + "--ulog-instance 1 --skip-rows 2"), 2,
                           "is a ULog: --no-header, --columns and --skip-rows apply to CSV logs",
                           out, "skip-rows");
  test::ExpectCleanFailure(test::RunCli(fit + "--ulog-instance 300"), 2, "--ulog-instance", out,
                           "instance out of range");
  test::ExpectCleanFailure(test::RunCli(fit + "--ulog-instance 1 --ulog-topic vehicle_imu"), 3,
                           "vehicle_imu", out, "topic absent");
  // The model records the unit of its target: the ULog's columns are in --ulog-units.
  test::ExpectCleanFailure(test::RunCli("fit '" + ulg + "' -t x_rads -T temperature_c --mode "
                                        "compensate --ulog-instance 1 --ulog-units rads -o '" +
                                        out + "'"),
                           2,
                           "--units dph: " + ulg + " is a ULog read in --ulog-units rads", out,
                           "units differ");
}

}  // namespace
}  // namespace gyrodrift
