// The study's models go through the fit and evaluate tasks (issue 25): the settings it gives them
// (internal::StudyFitSettings) must map onto the study's own drift options, so that what the
// report records (StudyResult::drift_options) is what the models were fitted with.
#include <gtest/gtest.h>

#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/study/study.h"
#include "study/study_steps.h"  // private to src/study

namespace gyrodrift::study {
namespace {

StudyResult Settled(bool simulated) {
  StudyResult s;
  s.options.ensemble_size = 7;
  s.options.realisations = 30;
  s.options.seed = 5;
  s.rate_hz = 2.0;
  s.threads = 3;
  s.simulated = simulated;
  s.drift_options = internal::StudyDriftOptions(s.options, s.rate_hz, simulated);
  return s;
}

TEST(StudySettings, TheTasksSeeTheStudysDriftOptions) {
  for (bool simulated : {true, false}) {
    const StudyResult s = Settled(simulated);
    drift::DriftOptions expected = s.drift_options;
    expected.mode = drift::Mode::kPredict;
    expected.reference_c.reset();  // a compensate-mode setting
    EXPECT_EQ(drift::MakeDriftOptions(internal::StudyFitSettings(s, drift::Mode::kPredict)),
              expected)
        << "simulated " << simulated;
    expected = s.drift_options;
    expected.mode = drift::Mode::kCompensate;
    expected.method = drift::Method::kThermal;  // "auto" in compensate mode
    const drift::FitSettings compensate = internal::StudyFitSettings(s, drift::Mode::kCompensate);
    EXPECT_EQ(drift::MakeDriftOptions(compensate), expected) << "simulated " << simulated;
    EXPECT_EQ(drift::MakeExecution(compensate).threads, 3);
  }
  // The simulated study references the estimate to 20 degC (StudyDriftOptions).
  EXPECT_EQ(
      internal::StudyFitSettings(Settled(true), drift::Mode::kCompensate).reference_temperature,
      20.0);
}

}  // namespace
}  // namespace gyrodrift::study
