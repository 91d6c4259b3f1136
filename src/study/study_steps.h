// Private to src/study: what the steps, the tables, the files and the report share.
#pragma once

#include <string>

#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/study/study.h"

namespace gyrodrift::study::internal {

// The models' options for a record sampled at rate_hz. The simulated study references the
// estimate to equilibrium at 20 degC, where the simulator's truth is zero and its turn-on bias,
// drawn anew for each run, is not (its convention, docs/drift.md 1.3); a log keeps the fitted
// intercept, the library default.
drift::DriftOptions StudyDriftOptions(const StudyOptions& options, double rate_hz, bool simulated);

// The study's models as the fit and evaluate tasks take them: StudyDriftOptions' settings in
// `mode` (s.rate_hz, s.threads; a temperature channel and the reference in compensate mode only,
// the predict-mode models being on the output alone). The method is left "auto".
drift::FitSettings StudyFitSettings(const StudyResult& s, drift::Mode mode);

// The group of IMF k (1-based): "noise", "mixed" or "drift" (beyond the listed IMFs: with the
// residue, so drift).
std::string GroupOf(const selection::SelectionResult& selection, int k);

// The study's tables, from the results of their step (study_tables.cc).
void FillPredictTable(StudyResult& s);
void FillCompensateTable(StudyResult& s);
void FillNoiseTermsTable(StudyResult& s);
void FillSettingsTable(StudyResult& s);
// total_s: wall time from the start of the study (reading a log included) to the report.
void FillTimingTable(StudyResult& s, double total_s);

}  // namespace gyrodrift::study::internal
