// The evaluate task's settings (tasks/evaluate_task.h): each maps onto its field of
// drift::EvaluationOptions, defaults are the library's, and a refusal names the field.
#include "gyrodrift/tasks/evaluate_task.h"

#include <gtest/gtest.h>

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

TEST(EvaluateTask, CausalEnsembleSizesTheWindowsDecompositions) {
  // The study sizes the causal windows' decompositions with its own ensemble.
  EvaluateSettings s = Predict();
  s.window = 64;
  s.causal_ensemble = 7;
  const drift::EvaluationOptions e = s.Options();
  EXPECT_EQ(e.causal.window, 64);
  EXPECT_EQ(e.causal.ensemble_size, 7);
  s.causal_ensemble = -1;
  try {
    (void)s.Options();
    ADD_FAILURE() << "a negative causal ensemble was accepted";
  } catch (const OptionError& error) {
    EXPECT_EQ(error.option(), "causal.ensemble_size");
  }
}

}  // namespace
}  // namespace gyrodrift::tasks
