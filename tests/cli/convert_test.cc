// gyrodrift convert, run as a user would on the real PX4 logs of ../shared/testdata: the listing
// shows the three gyro instances with their temperature, every instance converts to a CSV whose
// first row is pyulog's first sample (in deg/h, and in rad/s on request), and bad requests fail
// cleanly without touching the log.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "gyrodrift/io/csv.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

constexpr double kDphPerRads = 180.0 / M_PI * 3600.0;

std::string Log() { return test::TestDataPath("px4_ulog_samples/sample_log_small.ulg"); }

TEST(ConvertCli, ListsTheThreeGyroInstancesWithTheirTemperature) {
  const test::CommandResult r = test::RunCli("convert '" + Log() + "' --list");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int gyros = 0;
  std::size_t at = 0;
  while ((at = r.out.find("\nsensor_gyro ", at)) != std::string::npos) {
    const std::string line = r.out.substr(at + 1, r.out.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find("temperature"), std::string::npos) << line;
    EXPECT_NE(line.find(" 6 "), std::string::npos) << line;  // samples
    ++gyros;
    ++at;
  }
  EXPECT_EQ(gyros, 3) << r.out;
  // Each instance's device_id (what export --format px4 needs), as pyulog reads it.
  for (const char* id : {"device_id of sensor_gyro instance 0: 2424842\n",
                         "device_id of sensor_gyro instance 1: 3670050\n",
                         "device_id of sensor_gyro instance 2: 2621474\n"}) {
    EXPECT_NE(r.out.find(id), std::string::npos) << id << r.out;
  }
}

TEST(ConvertCli, EveryInstanceToCsvInDegreesPerHour) {
  const std::string dir = test::TempDir("cli_convert");
  const test::CommandResult r =
      test::RunCli("convert '" + Log() + "' --instance all -o '" + dir + "/gyro.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // pyulog's first sample of each instance: time stamp (us), x (rad/s), temperature (degC).
  const double first[3][3] = {{21312030, -0.04130320996046066, 40.02537155151367},
                              {21311176, 0.017656758427619934, 28.246023178100586},
                              {21311601, -0.0039059696719050407, 29.62611198425293}};
  for (int i = 0; i < 3; ++i) {
    const io::CsvTable t = io::CsvTable::Read(dir + "/gyro_" + std::to_string(i) + ".csv");
    EXPECT_EQ(t.header(),
              (std::vector<std::string>{"time_s", "x_dph", "y_dph", "z_dph", "temperature_c"}));
    ASSERT_EQ(t.rows(), 6);
    EXPECT_DOUBLE_EQ(t.Column("time_s")[0], first[i][0] * 1e-6);
    EXPECT_NEAR(t.Column("x_dph")[0], first[i][1] * kDphPerRads, 1e-9);
    EXPECT_EQ(t.Column("temperature_c")[0], first[i][2]);
  }
  const test::CommandResult rads = test::RunCli("convert '" + Log() + "' --units rads -q -o '" +
                                                dir + "/rads.csv'");
  ASSERT_EQ(rads.exit_code, 0) << rads.err;
  EXPECT_NEAR(io::CsvTable::Read(dir + "/rads.csv").Column("x_rads")[0], first[0][1], 1e-15);
}

TEST(ConvertCli, BadRequestsFailCleanly) {
  const std::string dir = test::TempDir("cli_convert_bad");
  const std::string out = dir + "/g.csv";
  test::ExpectCleanFailure(test::RunCli("convert '" + Log() + "' --instance 7 -o '" + out + "'"),
                           3, "no samples of sensor_gyro instance 7", out, "instance");
  test::ExpectCleanFailure(test::RunCli("convert '" + Log() + "' --instance x -o '" + out + "'"),
                           2, "--instance = x: must be an integer in [0, 255] or all", out,
                           "instance text");
  test::ExpectCleanFailure(
      test::RunCli("convert '" + Log() + "' --topic no_topic -o '" + out + "'"), 3,
      "no samples of no_topic", out, "topic");
  test::ExpectCleanFailure(test::RunCli("convert '" + Log() + "' --axes x,w -o '" + out + "'"),
                           3, "has no field \"w\"", out, "field");
  const std::string csv = dir + "/not_a_log.csv";
  ASSERT_EQ(test::RunShell("printf 'time_s,x\\n0,1\\n' > '" + csv + "'").exit_code, 0);
  test::ExpectCleanFailure(test::RunCli("convert '" + csv + "' -o '" + out + "'"), 3,
                           "not a readable ULog file: no ULog header", out, "csv");
}

}  // namespace
}  // namespace gyrodrift
