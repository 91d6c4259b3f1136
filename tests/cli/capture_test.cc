// Serial-terminal captures as published (../shared/testdata/bmi270_two_temperature: a PuTTY
// banner, no header, no time column, damaged lines): fit on the cold capture and compensate the
// hot one with --no-header --columns, --skip-rows, --bad-lines skip and --rate-hz, and the report
// says what was skipped and what was assumed. Without the flags the capture is refused, naming the
// line; the flags are refused when they do not go together.
#include <gtest/gtest.h>

#include "gyrodrift/io/csv.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

const std::string kCapture = "--no-header --columns temp_c,ax,ay,az,gx,gy,gz --skip-rows 1 ";

std::string Log(const std::string& name) {
  return "'" + test::TestDataPath("bmi270_two_temperature/" + name) + "'";
}

TEST(CaptureCli, BothBmi270CapturesGoThroughFitAndCompensate) {
  const std::string d = test::TempDir("cli_capture");
  const test::CommandResult fit =
      test::RunCli("fit " + Log("BMI_270_cold_test_.csv") + " " + kCapture +
                   "--bad-lines skip -t gx,gy,gz -T temp_c --mode compensate --units dps -o '" + d +
                   "/bmi.json'");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const std::string said = fit.out + fit.err;
  EXPECT_NE(said.find("2 damaged lines skipped (--bad-lines skip): lines 9, 3258"),
            std::string::npos)
      << said;
  // No time column and no --rate-hz: the rate is assumed, and said so before the work.
  EXPECT_NE(said.find("1 Hz"), std::string::npos) << said;
  const test::CommandResult given = test::RunCli(
      "fit " + Log("BMI_270_cold_test_.csv") + " " + kCapture +
      "--bad-lines skip --rate-hz 10 -t gx -T temp_c --mode compensate --units dps -q -o '" + d +
      "/bmi10.json'");
  ASSERT_EQ(given.exit_code, 0) << given.err;
  const test::CommandResult comp =
      test::RunCli("compensate '" + d + "/bmi.json' " + Log("BMI_270_hot_test.csv") + " " +
                   kCapture + "--bad-lines skip -o '" + d + "/hot.csv'");
  ASSERT_EQ(comp.exit_code, 0) << comp.err;
  EXPECT_NE((comp.out + comp.err).find("3 damaged lines skipped (--bad-lines skip): lines 2, 13, "
                                       "6537"),
            std::string::npos)
      << comp.out << comp.err;
  // Every line but the banner and the three damaged ones.
  EXPECT_EQ(io::CsvTable::Read(d + "/hot.csv").rows(), 6533);
}

TEST(CaptureCli, WithoutTheFlagsOrWithHalfOfThemTheCaptureIsRefused) {
  const std::string out = test::TempDir("cli_capture_bad") + "/m.json";
  const std::string fit = "fit " + Log("BMI_270_cold_test_.csv") +
                          " -t gx -T temp_c --mode compensate -o '" + out + "' ";
  test::ExpectCleanFailure(test::RunCli(fit), 3, "line 2 has 7 cells, the header has 1", out,
                           "as published");
  test::ExpectCleanFailure(test::RunCli(fit + kCapture), 3,
                           "line 3258 has 1 cells, the header has 7 (the names given)", out,
                           "damaged line");
  test::ExpectCleanFailure(test::RunCli(fit + "--columns temp_c,gx"), 2, "add --no-header", out,
                           "columns alone");
  test::ExpectCleanFailure(test::RunCli(fit + "--no-header"), 2, "--no-header needs --columns",
                           out, "no-header alone");
  test::ExpectCleanFailure(test::RunCli(fit + kCapture + "--bad-lines maybe"), 2, "--bad-lines",
                           out, "bad choice");
}

}  // namespace
}  // namespace gyrodrift
