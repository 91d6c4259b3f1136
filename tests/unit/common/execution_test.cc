// The execution context (execution.h): the one thread-count check accepts exactly [0, 1024] with
// the documented message, Validate applies it, and Report forwards to progress only when one is
// set (an empty callback is the default and must not be called).
#include "gyrodrift/common/execution.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"

namespace gyrodrift {
namespace {

// The message of the OptionError ValidateThreads(threads) throws, or "" when it accepts.
std::string Refusal(int threads) {
  try {
    ValidateThreads(threads);
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "threads");
    EXPECT_EQ(e.value(), std::to_string(threads));
    return e.what();
  }
  return "";
}

TEST(ValidateThreads, AcceptsZeroToTenTwentyFour) {
  for (int threads : {0, 1, 2, 64, 1023, 1024}) EXPECT_EQ(Refusal(threads), "") << threads;
}

TEST(ValidateThreads, RefusesTheRestWithTheDocumentedMessage) {
  EXPECT_EQ(Refusal(-1), "threads = -1: must be an integer in [0, 1024] (0 = all cores)");
  EXPECT_EQ(Refusal(1025), "threads = 1025: must be an integer in [0, 1024] (0 = all cores)");
  for (int threads : {std::numeric_limits<int>::min(), std::numeric_limits<int>::max()}) {
    EXPECT_NE(Refusal(threads), "") << threads;
  }
  // A usage mistake: the CLI's exit code 2.
  EXPECT_THROW(ValidateThreads(-1), UsageError);
}

TEST(Execution, ValidateChecksTheThreadCount) {
  EXPECT_NO_THROW(Execution{}.Validate());  // the default, every core
  EXPECT_NO_THROW(Execution{.threads = 1024}.Validate());
  EXPECT_THROW(Execution{.threads = -3}.Validate(), OptionError);
  EXPECT_THROW(Execution{.threads = 2000}.Validate(), OptionError);
}

TEST(Execution, ReportCallsProgressOnlyWhenSet) {
  const Execution quiet;
  EXPECT_FALSE(quiet.progress);
  EXPECT_NO_THROW(quiet.Report(0.5, "decompose"));  // an empty std::function would throw

  std::vector<std::pair<double, std::string>> calls;
  Execution watched{.threads = 1, .progress = [&](double fraction, std::string_view step) {
                      calls.emplace_back(fraction, std::string(step));
                    }};
  watched.Report(0.0, "decompose");
  watched.Report(1.0, "");
  const std::vector<std::pair<double, std::string>> expected = {{0.0, "decompose"}, {1.0, ""}};
  EXPECT_EQ(calls, expected);
}

TEST(Execution, AnExceptionFromProgressLeavesReport) {
  // The documented way to cancel a call: throw from progress.
  struct Cancelled {};
  const Execution cancel{.progress = [](double, std::string_view) { throw Cancelled{}; }};
  EXPECT_THROW(cancel.Report(0.25, "fit"), Cancelled);
}

}  // namespace
}  // namespace gyrodrift
