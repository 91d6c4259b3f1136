// A fleet of serial-terminal captures (../shared/testdata/bmi270_two_temperature: a PuTTY banner,
// no header, no time column, damaged lines): the manifest takes every log setting as a key
// (names, skip_rows, bad_lines, rate_hz; tasks::LogOptionsFromJson), so `gyrodrift calibrate`
// reads the captures as `gyrodrift fit` and `compensate` read them with the flags: the unit's
// model file is byte for byte the one fit writes, and its compensated verification log the one
// compensate writes.
#include <gtest/gtest.h>

#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

std::string Log(const std::string& name) {
  return test::TestDataPath("bmi270_two_temperature/" + name);
}

TEST(CaptureCalibrateCli, TheFleetReadsCapturesAsFitAndCompensateDo) {
  const std::string d = test::TempDir("cli_capture_calibrate");
  const std::string cold = Log("BMI_270_cold_test_.csv"), hot = Log("BMI_270_hot_test.csv");
  std::string manifest =
      "rate_unit = \"dps\"\nrate_hz = 10\nnames = [\"temp_c\", \"ax\", \"ay\", \"az\", \"gx\", "
      "\"gy\", \"gz\"]\nskip_rows = 1\nbad_lines = \"skip\"\n";
  for (const char* axis : {"gx", "gy", "gz"}) {
    manifest += std::string("[[axis]]\ntarget = \"") + axis + "\"\ntemperature = \"temp_c\"\n";
  }
  manifest += "[[unit]]\nserial = \"BMI\"\ncalibration = \"" + cold + "\"\nverification = \"" +
              hot + "\"\n";
  io::WriteFileAtomically(d + "/fleet.toml", manifest);
  const test::CommandResult cal =
      test::RunCli("calibrate '" + d + "/fleet.toml' -o '" + d + "/out' -q");
  ASSERT_EQ(cal.exit_code, 0) << cal.out << cal.err;

  const std::string flags =
      " --no-header --columns temp_c,ax,ay,az,gx,gy,gz --skip-rows 1 --bad-lines skip ";
  const test::CommandResult fit =
      test::RunCli("fit '" + cold + "'" + flags +
                   "--rate-hz 10 -t gx,gy,gz -T temp_c --mode compensate --units dps -q -o '" + d +
                   "/bmi.json'");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_EQ(io::ReadTextFile(d + "/out/BMI/model.json"), io::ReadTextFile(d + "/bmi.json"));

  // compensate takes its blocks' rate from the model (10 Hz), as the fleet from rate_hz.
  const test::CommandResult comp = test::RunCli("compensate '" + d + "/bmi.json' '" + hot + "'" +
                                                flags + "-q -o '" + d + "/hot.csv'");
  ASSERT_EQ(comp.exit_code, 0) << comp.err;
  EXPECT_EQ(io::ReadTextFile(d + "/out/BMI/verification_1_compensated.csv"),
            io::ReadTextFile(d + "/hot.csv"));
  // Every line of the hot capture but the banner and its three damaged lines.
  EXPECT_NE(io::ReadTextFile(d + "/out/fleet.csv").find(",6533,"), std::string::npos);
}

}  // namespace
}  // namespace gyrodrift
