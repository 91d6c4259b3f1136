// The evaluate task's settings (tasks/evaluate_task.h): each maps onto its field of
// drift::EvaluationOptions, defaults are the library's, and a refusal names the field.
#include "gyrodrift/tasks/evaluate_task.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
  s.causal = {.window = 64, .ensemble_size = 7, .mirror = 0.25, .windows = 5};
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
  bad.causal.ensemble_size = -1;
  EXPECT_EQ(refused(bad), "causal.ensemble_size");
  bad = s;
  bad.causal.mirror = 1.5;
  EXPECT_EQ(refused(bad), "causal.mirror");
  bad = s;
  bad.causal.windows = 0;
  EXPECT_EQ(refused(bad), "causal.windows");
}

TEST(EvaluateTask, HiddenUnitsReachTheElmInCompensateMode) {
  // docs/cli.md: --hidden changes only the ELM methods. In compensate mode that is elm (ms-elm's
  // sub-models are linear there): its count was refused as if ms-elm had been asked for.
  const Eigen::Index n = 2400;
  Eigen::VectorXd temperature(n), y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    temperature[i] = 20.0 + 10.0 * std::sin(static_cast<double>(i) / 300.0);
    y[i] = 0.05 * temperature[i] + 0.01 * std::cos(static_cast<double>(i) * 1.7);
  }
  EvaluateSettings s{.fit = {.mode = "compensate", .hidden = "7", .has_temperature = true},
                     .methods = "elm,poly"};
  s.fit.threads = 1;
  const EvaluateRun run = RunEvaluate(y, temperature, Eigen::VectorXd(), s);
  EXPECT_EQ(run.base.learner.elm.selection, elm::Selection::kFixed);
  EXPECT_EQ(run.base.learner.elm.hidden_units, 7);
  EXPECT_EQ(run.base.method, drift::Method::kMsElm);  // the stand-in the sidecar records
  const auto elm_rows =
      std::count_if(run.result.rows.begin(), run.result.rows.end(),
                    [](const auto& r) { return r.method == drift::Method::kElm; });
  EXPECT_GT(elm_rows, 0);
  // With the identified methods' settings beside it (they were refused as elm's), and a count
  // that is none still refused, naming the setting.
  s.fit.hysteresis = "on";
  s.fit.standard_errors = 0.0;
  s.methods = "thermal,elm";
  EXPECT_NO_THROW(s.Validate());
  s.fit.hidden = "0";
  try {
    s.Validate();
    ADD_FAILURE() << "accepted";
  } catch (const OptionError& error) {
    EXPECT_EQ(error.option(), "hidden");
  }
}

}  // namespace
}  // namespace gyrodrift::tasks
