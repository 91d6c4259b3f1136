// gyrodrift plan, run as a user would: an 8-h programme, followed by `simulate --profile` and
// `fit --mode compensate`, gives a run the fit identifies without a warning or advice; a plan
// that cannot fit is refused with what would, and nothing is written.
#include <gtest/gtest.h>

#include "gyrodrift/io/csv.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

TEST(PlanCli, APlanFollowedBySimulateAndFitGivesNoIdentificationWarning) {
  const std::string d = test::TempDir("cli_plan");
  const test::CommandResult plan =
      test::RunCli("plan --hours 8 --min -20 --max 60 -o '" + d + "/plan.csv'");
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  EXPECT_NE(plan.out.find("cooling at the slow rate"), std::string::npos) << plan.out;
  EXPECT_EQ(io::CsvTable::Read(d + "/plan.csv").header(),
            (std::vector<std::string>{"time_s", "temperature_c"}));
  ASSERT_EQ(test::RunCli("simulate --profile '" + d + "/plan.csv' --seed 5 -q -o '" + d +
                         "/run.csv'")
                .exit_code,
            0);
  const test::CommandResult fit =
      test::RunCli("fit '" + d + "/run.csv' -t rate_dph -T temperature_c --mode compensate -o '" +
                   d + "/model.json'");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_EQ(fit.err.find("warning:"), std::string::npos) << fit.err;
  EXPECT_EQ(fit.err.find("advice:"), std::string::npos) << fit.err;
  EXPECT_EQ(fit.out.find("advice:"), std::string::npos) << fit.out;
}

TEST(PlanCli, APlanThatCannotFitIsRefused) {
  const std::string out = test::TempDir("cli_plan_bad") + "/plan.csv";
  test::ExpectCleanFailure(test::RunCli("plan --hours 4 --min -40 --max 80 -o '" + out + "'"), 2,
                           "it needs 8.4 h or more", out, "too short");
  test::ExpectCleanFailure(test::RunCli("plan --min 20 --max 25 -o '" + out + "'"), 2,
                           "--max = 25: must be in [35, 200]",
                           out, "too narrow");
  // No top can be 15 K above a bottom of 199 degC: the bottom is named, not the top.
  test::ExpectCleanFailure(test::RunCli("plan --min 199 --max 200 -o '" + out + "'"), 2,
                           "--min = 199: must be in [-100, 185]", out, "bottom too high");
}

}  // namespace
}  // namespace gyrodrift
