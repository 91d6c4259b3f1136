// A PX4 ULog given directly to fit and compensate: the same numbers as its converted CSV (the
// model and the compensated log byte for byte), the instance chosen by --ulog-instance, the log
// untouched, and the CSV-only flags refused for a ULog.
#include <gtest/gtest.h>

#include <cmath>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"
#include "support/ulog_writer.h"

namespace gyrodrift {
namespace {

constexpr double kRadsPerDph = M_PI / 180.0 / 3600.0;

// A 40-min thermal log as a ULog: x the log's rate, y its opposite, z half of it.
std::string WriteLog(const std::string& dir) {
  io::WriteFileAtomically(dir + "/log.csv", test::ThermalLogCsv(2400, 11));
  std::vector<std::string> header;
  const Eigen::MatrixXd m = test::ReadCsvMatrix(dir + "/log.csv", &header);
  EXPECT_EQ(header[1], "rate_dph");
  Eigen::MatrixXd xyz(m.rows(), 3);
  xyz << m.col(1) * kRadsPerDph, -m.col(1) * kRadsPerDph, 0.5 * m.col(1) * kRadsPerDph;
  test::WriteSensorGyroUlog(dir + "/log.ulg", m.col(0), xyz, m.col(2), 2490378, 1);
  return dir + "/log.ulg";
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
