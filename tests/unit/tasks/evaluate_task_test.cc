// The evaluate task's settings (tasks/evaluate_task.h): each maps onto its field of
// drift::EvaluationOptions, defaults are the library's, and a refusal names the field.
#include "gyrodrift/tasks/evaluate_task.h"

#include <gtest/gtest.h>

#include <string>

#include "gyrodrift/common/error.h"

namespace gyrodrift::tasks {
namespace {

EvaluateSettings Predict() { return {.fit = {.mode = "predict"}}; }

TEST(EvaluateTask, DefaultsAreTheLibrarys) {
  const drift::EvaluationOptions e = Predict().Options();
  const drift::EvaluationOptions library;
  EXPECT_EQ(e.split, library.split);
  EXPECT_EQ(e.repeats, library.repeats);
  EXPECT_EQ(e.horizon, library.horizon);
  EXPECT_EQ(e.causal, library.causal);
  EXPECT_EQ(e.methods, drift::AllMethods(drift::Mode::kPredict));
}

TEST(EvaluateTask, CausalSettingsReachTheWindowsDecompositions) {
  // --window, --mirror, --windows and --causal-ensemble (the study sets the first three).
  EvaluateSettings s = Predict();
  s.window = 64;
  s.mirror = 0.25;
  s.windows = 5;
  s.causal_ensemble = 7;
  const drift::EvaluationOptions e = s.Options();
  EXPECT_EQ(e.causal.window, 64);
  EXPECT_EQ(e.causal.mirror, 0.25);
  EXPECT_EQ(e.causal.windows, 5);
  EXPECT_EQ(e.causal.ensemble_size, 7);
  // The option each refusal names.
  const auto refused = [](const EvaluateSettings& bad) -> std::string {
    try {
      (void)bad.Options();
    } catch (const OptionError& error) {
      return error.option();
    }
    return "(accepted)";
  };
  EvaluateSettings bad = s;
  bad.causal_ensemble = -1;
  EXPECT_EQ(refused(bad), "causal.ensemble_size");
  bad = s;
  bad.mirror = 1.5;
  EXPECT_EQ(refused(bad), "causal.mirror");
  bad = s;
  bad.windows = 0;
  EXPECT_EQ(refused(bad), "causal.windows");
}

}  // namespace
}  // namespace gyrodrift::tasks
