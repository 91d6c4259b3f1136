// The study module: StudyOptions and StudyLog refuse bad values naming the field; small studies
// (a log, a short simulation) produce the expected tables, observer calls, files and report
// sections. The Table itself is table_test.cc's, the files' rendering and writing
// study_files_test.cc's.
#include "gyrodrift/study/study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/study/study_files.h"
#include "gyrodrift/study/table.h"
#include "unit/study/chamber_log.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift::study {
namespace {

// The option a call refused, or "" when it did not throw an OptionError.
template <typename F>
std::string RefusedOption(F&& call) {
  try {
    call();
  } catch (const OptionError& e) {
    return e.option();
  }
  return "";
}

// The cheapest settings that still run every step.
StudyOptions Quick(std::vector<drift::Method> methods) {
  StudyOptions o;
  o.ensemble_size = 4;
  o.realisations = 20;
  o.causal.window = 32;
  o.duration_s = 2 * 3600.0;
  o.methods = std::move(methods);
  return o;
}

std::set<std::string> Pairs(const Table& t) {
  std::set<std::string> pairs;
  for (const auto& row : t.csv) pairs.insert(row[0] + "/" + row[1]);
  return pairs;
}

std::set<std::string> Names(const std::vector<StudyFile>& files) {
  std::set<std::string> names;
  for (const auto& f : files) names.insert(f.name);
  return names;
}

TEST(StudyOptions, DefaultsAreValid) { EXPECT_NO_THROW(StudyOptions().Validate()); }

TEST(StudyOptions, ValidateNamesTheField) {
  auto refused = [](auto change) {
    StudyOptions o;
    change(o);
    return RefusedOption([&] { o.Validate(); });
  };
  EXPECT_EQ(refused([](StudyOptions& o) { o.ensemble_size = 0; }), "ensemble_size");
  EXPECT_EQ(refused([](StudyOptions& o) { o.ensemble_size = 100001; }), "ensemble_size");
  EXPECT_EQ(refused([](StudyOptions& o) { o.duration_s = 5400.0; }), "duration_s");
  EXPECT_EQ(refused([](StudyOptions& o) { o.duration_s = std::nan(""); }), "duration_s");
  EXPECT_EQ(refused([](StudyOptions& o) { o.methods.clear(); }), "methods");
  EXPECT_EQ(refused([](StudyOptions& o) {
              o.methods = {drift::Method::kElm, drift::Method::kPoly, drift::Method::kElm};
            }),
            "methods");
  // Ranges the library owns name the study's field that set them.
  EXPECT_EQ(refused([](StudyOptions& o) { o.causal.window = 4; }), "causal.window");
  EXPECT_EQ(refused([](StudyOptions& o) { o.realisations = 3; }), "realisations");
}

TEST(StudyLog, RefusesWhatTheStudyCannotUse) {
  const StudyOptions options = Quick({drift::Method::kPoly});
  StudyLog log = ChamberLog();
  log.output.conservativeResize(63);
  log.temperature.conservativeResize(63);
  EXPECT_THROW(RunStudy(options, log), DataError);
  log = ChamberLog();
  log.temperature.conservativeResize(log.output.size() - 1);
  EXPECT_THROW(RunStudy(options, log), DataError);
  log = ChamberLog();
  log.rate_hz = 0.0;
  EXPECT_EQ(RefusedOption([&] { RunStudy(options, log); }), "rate_hz");
  // Options are checked before the data.
  StudyOptions bad = options;
  bad.ensemble_size = 0;
  EXPECT_EQ(RefusedOption([&] { RunStudy(bad, log); }), "ensemble_size");
  // And so is the context's thread count.
  EXPECT_EQ(RefusedOption([&] { RunStudy(options, ChamberLog(), {.threads = -1}); }), "threads");
}

TEST(Study, LogStudyGivesTablesFilesAndReport) {
  const StudyOptions options = Quick({drift::Method::kMsElm, drift::Method::kPoly});
  const StudyLog log = ChamberLog();
  std::vector<int> begun, done;
  int last_stage = -1;
  bool fractions_in_range = true;
  StudyContext context{.threads = 2};
  context.progress = [&](int stage, double fraction, const std::string&) {
    if (stage != last_stage) begun.push_back(stage);
    last_stage = stage;
    fractions_in_range = fractions_in_range && fraction >= 0.0 && fraction <= 1.0;
  };
  std::string summaries;
  context.stage_done = [&](int stage, const std::string& summary) {
    done.push_back(stage);
    summaries += summary;
  };
  const StudyResult s = RunStudy(options, log, context);

  EXPECT_EQ(begun, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(done, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(fractions_in_range);
  EXPECT_EQ(summaries.rfind("1. read chamber.csv: 2400 samples of rate_dph at 1 Hz (given)\n", 0),
            0u)
      << summaries;
  for (const char* part : {"\n2. ", "\n3. Predict mode", "\n4. Compensate mode", "\n5. IEEE 952"})
    EXPECT_NE(summaries.find(part), std::string::npos) << part;

  EXPECT_FALSE(s.simulated);
  EXPECT_EQ(s.unit, "deg/h");
  EXPECT_FALSE(s.drift_options.reference_c);  // a log keeps the fitted intercept
  EXPECT_EQ(s.threads, 2);
  EXPECT_GE(s.decomposition.num_imfs(), 3);
  // Every table opens with the references none and constant; predict mode adds the filters.
  std::set<std::string> both{"none/paper",   "none/causal", "constant/paper", "constant/causal",
                             "ms-elm/paper", "ms-elm/causal", "poly/paper",   "poly/causal"};
  EXPECT_EQ(Pairs(s.compensate_table), both);
  for (const char* m :
       {"persistence", "trailing-mean", "exp-smoothing", "kalman-level", "kalman-trend"}) {
    both.insert(std::string(m) + "/paper");
    both.insert(std::string(m) + "/causal");
  }
  EXPECT_EQ(Pairs(s.predict_table), both);
  for (const auto& row : s.compensate) {
    EXPECT_EQ(row.estimate.size(), s.compensate_reference.size());
    EXPECT_TRUE(std::isfinite(row.metrics.rmse));
  }
  EXPECT_EQ(s.compensated_by, "ms-elm (causal)");
  EXPECT_EQ(s.terms_table.csv.size(), 6u);  // five IEEE 952 terms and the minimum ADEV
  EXPECT_EQ(s.terms_table.header.size(), s.best_by.empty() ? 4u : 5u);
  ASSERT_EQ(s.stage_s.size(), 5u);
  EXPECT_EQ(s.stage_s[0].first, "read");
  EXPECT_EQ(s.timing_table.csv.size(), 6u);

  const std::vector<StudyFile> files = RenderStudyFiles(s, test::FakeDygraphs());
  EXPECT_EQ(Names(files),
            (std::set<std::string>{"imfs.csv", "selection.csv", "predict_table.csv",
                                   "compensate_table.csv", "noise_terms.csv",
                                   "predict_estimates.csv", "compensate_estimates.csv",
                                   "allan.csv", "models/ms-elm_compensate.json",
                                   "models/poly_compensate.json", "report.html"}));
  for (const auto& f : files) {
    if (f.name == "predict_table.csv") {
      EXPECT_EQ(f.contents, s.predict_table.Csv());
    }
  }
  const std::string& html = files.back().contents;
  EXPECT_EQ(files.back().name, kStudyReportFile);
  for (const char* section :
       {"gyrodrift demo: chamber.csv", "1. The record", "2. BEEMDAN decomposition and mode selection",
        "3. Predict mode (the paper&#39;s task)", "4. Compensate mode: chronological split",
        "5. Allan deviation", "6. Settings and timing", "Selection curves", "IMF 1 ("}) {
    EXPECT_NE(html.find(section), std::string::npos) << section;
  }
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_EQ(check.tables, 5);  // predict, compensate, noise terms, settings, timing

  const nlohmann::json record = StudyRecord(s);
  for (const char* key :
       {"drift_options", "threads", "decomposition", "selection", "stages_s", "compensated_by"}) {
    EXPECT_TRUE(record.contains(key)) << key;
  }
  EXPECT_EQ(record["stages_s"].size(), 5u);
}

TEST(Study, ShortSimulationComparesRunsAAndB) {
  // thermal is compensate-only: predict mode runs poly alone.
  const StudyResult s =
      RunStudy(Quick({drift::Method::kPoly, drift::Method::kThermal}), {.threads = 2});
  EXPECT_TRUE(s.simulated);
  EXPECT_EQ(s.output.size(), 7200);
  EXPECT_EQ(s.run_b.samples, 7200);
  EXPECT_EQ(s.drift_options.reference_c, 20.0);  // the simulator's equilibrium
  EXPECT_EQ(Pairs(s.predict_table).size(), 16u);  // none, constant, poly and 5 filters, x 2
  EXPECT_TRUE(Pairs(s.predict_table).count("kalman-trend/causal"));
  EXPECT_EQ(Pairs(s.compensate_table),
            (std::set<std::string>{"none/train A test B", "constant/train A test B",
                                   "poly/train A test B", "thermal/train A test B"}));
  // Scored against run B's true drift: the identified thermal model removes most of it.
  for (const auto& row : s.compensate) {
    if (row.method == drift::Method::kThermal) {
      EXPECT_GT(row.share_removed, 0.5);
    }
  }
  // The first method (no ms-elm) that is not a reference.
  EXPECT_EQ(s.compensated_by, "poly (train A test B)");
  EXPECT_EQ(s.terms_table.header.back(), "simulator setting");
  const std::set<std::string> names = Names(RenderStudyFiles(s, test::FakeDygraphs()));
  EXPECT_TRUE(names.count("run_a.csv") && names.count("run_b.csv"));
  EXPECT_TRUE(names.count("models/thermal_compensate.json"));
}

TEST(Study, GroupingUsesTheStudysSeed) {
  // Issue 25: with fewer ensemble members than Monte-Carlo realisations the selection's white-noise
  // level draws its own realisations; they must come from the study's seed, not the default 1.
  StudyOptions o = Quick({drift::Method::kPoly});
  o.seed = 2;
  const StudyResult s = RunStudy(o, {.threads = 2});
  EXPECT_EQ(s.selection.noise_level_seed, 2u);
  // The same grouping as the selection of that decomposition with seed 2 throughout.
  selection::SelectionOptions sopt = s.drift_options.selection;
  sopt.monte_carlo.seed = 2;
  const selection::SelectionResult again = selection::SelectModes(s.output, s.decomposition, sopt);
  ASSERT_EQ(again.groups.size(), s.selection.groups.size());
  for (size_t g = 0; g < again.groups.size(); ++g) {
    EXPECT_EQ(again.groups[g].imfs, s.selection.groups[g].imfs);
  }
  EXPECT_EQ(again.Summary(), s.selection.Summary());
}

}  // namespace
}  // namespace gyrodrift::study
