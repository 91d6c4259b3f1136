// The study's tables (study_tables.cc), filled from hand-made step results so that every cell
// can be traced to the field it comes from: column order, one row per result in the results'
// order, the values unchanged in the CSV (only the shown text is rounded, to 4 significant digits
// for scores and 3 for seconds), the share removed as a percentage, and the noise-term columns
// that depend on the run (best method, simulation truth and setting).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/simulation/gyro_noise.h"
#include "gyrodrift/study/study.h"
#include "gyrodrift/study/table.h"
#include "study/study_steps.h"  // private to src/study: the Fill* functions under test

namespace gyrodrift::study {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

drift::EvaluationRow PredictRow(drift::Method method, drift::Protocol protocol, double rmse) {
  drift::EvaluationRow r;
  r.method = method;
  r.protocol = protocol;
  r.rmse = rmse;
  r.mae = rmse / 3.0;
  r.max_abs = rmse * 7.0;
  r.train_s = 1.23456;
  r.predict_s = 0.0456789;
  r.rmse_measured = rmse * 2.0;
  r.slow_removed = 0.75;
  return r;
}

// The column of `t` named `name` in row `row`: csv (full precision) or shown.
std::string Csv(const Table& t, size_t row, const std::string& name) {
  for (size_t c = 0; c < t.header.size(); ++c) {
    if (t.header[c] == name) return t.csv.at(row).at(c);
  }
  ADD_FAILURE() << "no column " << name;
  return "";
}
std::string Shown(const Table& t, size_t row, const std::string& name) {
  for (size_t c = 0; c < t.header.size(); ++c) {
    if (t.header[c] == name) return t.shown.at(row).at(c);
  }
  ADD_FAILURE() << "no column " << name;
  return "";
}

// The first cell of every row.
std::vector<std::string> FirstColumn(const Table& t) {
  std::vector<std::string> names;
  for (const auto& row : t.csv) names.push_back(row.at(0));
  return names;
}

TEST(PredictTable, OneRowPerEvaluationRowInItsOrder) {
  StudyResult s;
  s.simulated = true;
  s.predict.rows = {PredictRow(drift::Method::kMsElm, drift::Protocol::kPaper, 0.0123456789),
                    PredictRow(drift::Method::kMsElm, drift::Protocol::kCausal, 0.5),
                    PredictRow(drift::Method::kPoly, drift::Protocol::kPaper, kNan)};
  internal::FillPredictTable(s);
  const Table& t = s.predict_table;
  EXPECT_EQ(t.header,
            (std::vector<std::string>{"method", "protocol", "rmse", "mae", "max_abs",
                                      "rmse_measured", "slow_removed_%", "train_s", "predict_s"}));
  ASSERT_EQ(t.csv.size(), 3u);
  ASSERT_EQ(t.shown.size(), 3u);
  for (size_t i = 0; i < t.csv.size(); ++i) EXPECT_EQ(t.csv[i].size(), t.header.size()) << i;
  EXPECT_EQ(t.csv[1][0], "ms-elm");
  EXPECT_EQ(t.csv[1][1], "causal");
  EXPECT_EQ(t.csv[2][0], "poly");
  EXPECT_EQ(t.csv[2][1], "paper");
  // Full precision in the CSV, straight from the row.
  const drift::EvaluationRow& r = s.predict.rows[0];
  EXPECT_EQ(Csv(t, 0, "rmse"), io::FormatDouble(r.rmse));
  EXPECT_EQ(Csv(t, 0, "mae"), io::FormatDouble(r.mae));
  EXPECT_EQ(Csv(t, 0, "max_abs"), io::FormatDouble(r.max_abs));
  EXPECT_EQ(Csv(t, 0, "train_s"), io::FormatDouble(r.train_s));
  EXPECT_EQ(Csv(t, 0, "predict_s"), io::FormatDouble(r.predict_s));
  EXPECT_EQ(Csv(t, 0, "rmse_measured"), io::FormatDouble(r.rmse_measured));
  EXPECT_EQ(Csv(t, 0, "slow_removed_%"), io::FormatDouble(100.0 * r.slow_removed));
  // Scores shown to 4 significant digits, seconds to 3; a missing score is a dash.
  EXPECT_EQ(Shown(t, 0, "rmse"), "0.01235");
  EXPECT_EQ(Shown(t, 0, "train_s"), "1.23");
  EXPECT_EQ(Shown(t, 0, "predict_s"), "0.0457");
  EXPECT_EQ(Shown(t, 2, "rmse"), "-");
  // The title and caption say what the scores are against.
  EXPECT_NE(t.title.find("run A"), std::string::npos) << t.title;
  EXPECT_NE(t.caption.find("true drift"), std::string::npos) << t.caption;
  s.simulated = false;
  internal::FillPredictTable(s);
  EXPECT_NE(s.predict_table.title.find("the record"), std::string::npos);
  EXPECT_NE(s.predict_table.caption.find("measured output"), std::string::npos);
}

TEST(CompensateTable, SharesRemovedArePercentagesAndProtocolsAreKept) {
  StudyResult s;
  s.simulated = true;
  StudyResult::CompensateRow a;
  a.method = drift::Method::kThermal;
  a.protocol = "train A test B";
  a.metrics = {0.001234567, 0.0009, 0.004};
  a.share_removed = 0.9512345;
  a.train_s = 0.25;
  a.estimate_s = 0.0012345;
  StudyResult::CompensateRow b = a;
  b.method = drift::Method::kPoly;
  b.share_removed = -0.25;  // an estimate that adds error: kept negative, not clipped
  s.compensate = {a, b};
  internal::FillCompensateTable(s);
  const Table& t = s.compensate_table;
  EXPECT_EQ(t.header,
            (std::vector<std::string>{"method", "protocol", "rmse", "mae", "max_abs", "removed_%",
                                      "slow_removed_%", "train_s", "estimate_s"}));
  EXPECT_EQ(FirstColumn(t), (std::vector<std::string>{"thermal", "poly"}));
  EXPECT_EQ(Csv(t, 0, "protocol"), "train A test B");
  EXPECT_EQ(Csv(t, 0, "rmse"), io::FormatDouble(a.metrics.rmse));
  EXPECT_EQ(Csv(t, 0, "mae"), io::FormatDouble(a.metrics.mae));
  EXPECT_EQ(Csv(t, 0, "max_abs"), io::FormatDouble(a.metrics.max_abs));
  EXPECT_EQ(Csv(t, 0, "removed_%"), io::FormatDouble(100.0 * a.share_removed));
  EXPECT_EQ(Shown(t, 0, "removed_%"), "95.12");
  EXPECT_EQ(Shown(t, 1, "removed_%"), "-25");
  EXPECT_EQ(Shown(t, 0, "slow_removed_%"), "-");  // not set: a record shorter than 10 min
  EXPECT_EQ(Csv(t, 0, "estimate_s"), io::FormatDouble(a.estimate_s));
  EXPECT_EQ(Shown(t, 0, "estimate_s"), "0.00123");
  EXPECT_NE(t.title.find("run A"), std::string::npos);
  s.simulated = false;
  internal::FillCompensateTable(s);
  EXPECT_NE(s.compensate_table.title.find("chronological split"), std::string::npos);
}

allan::NoiseTerms Terms(double n, double b, bool b_identified, double min_dev) {
  allan::NoiseTerms terms;
  terms.n_dpsh.value = n;
  terms.n_dpsh.identified = true;
  terms.b_dph.value = b;
  terms.b_dph.identified = b_identified;
  terms.min_dev_dph = min_dev;
  return terms;
}

TEST(NoiseTermsTable, ColumnsFollowTheRunAndUnidentifiedTermsAreDashes) {
  StudyResult s;
  s.compensated_by = "ms-elm (causal)";
  s.terms_raw = Terms(0.004, 0.02, true, 0.015);
  // A term the fit did not identify has a value of 0 that is not a measurement.
  s.terms_compensated = Terms(0.0045, 0.0, false, 0.011);
  internal::FillNoiseTermsTable(s);
  const Table& t = s.terms_table;
  EXPECT_EQ(t.header,
            (std::vector<std::string>{"term", "unit", "raw", "compensated: ms-elm (causal)"}));
  EXPECT_EQ(FirstColumn(t),
            (std::vector<std::string>{"Q quantization", "N angle random walk", "B bias instability",
                                      "K rate random walk", "R rate ramp", "minimum ADEV"}));
  const std::string compensated = t.header[3];
  EXPECT_EQ(Csv(t, 1, "unit"), "deg/sqrt(h)");
  EXPECT_EQ(Csv(t, 1, "raw"), io::FormatDouble(0.004));
  EXPECT_EQ(Csv(t, 1, compensated), io::FormatDouble(0.0045));
  EXPECT_EQ(Csv(t, 2, "raw"), io::FormatDouble(0.02));
  EXPECT_EQ(Shown(t, 2, compensated), "-");
  EXPECT_EQ(Shown(t, 0, "raw"), "-");  // Q: not identified
  EXPECT_EQ(Csv(t, 5, "raw"), io::FormatDouble(0.015));
  EXPECT_EQ(Csv(t, 5, compensated), io::FormatDouble(0.011));

  // With a clearly better method and a simulation: its column, then the noise alone and the
  // simulator's setting; a fit that failed (no terms) is a column of dashes.
  // (A fresh result: the Fill functions append rows to the table they are given.)
  StudyResult r;
  r.compensated_by = s.compensated_by;
  r.terms_raw = s.terms_raw;
  r.terms_compensated = s.terms_compensated;
  r.best_by = "thermal (train A test B)";
  r.simulated = true;
  r.terms_noise = Terms(0.00458, 0.01, true, 0.009);
  internal::FillNoiseTermsTable(r);
  const Table& u = r.terms_table;
  EXPECT_EQ(u.header,
            (std::vector<std::string>{"term", "unit", "raw", "compensated: ms-elm (causal)",
                                      "compensated: thermal (train A test B)", "noise only (truth)",
                                      "simulator setting"}));
  ASSERT_EQ(u.csv.size(), 6u);
  for (size_t row = 0; row < u.csv.size(); ++row) {
    EXPECT_EQ(u.csv[row].size(), u.header.size());
    EXPECT_EQ(Shown(u, row, "compensated: thermal (train A test B)"), "-") << row;
  }
  const simulation::NoiseParameters np =
      simulation::PresetParameters(simulation::Preset::kNavigation).noise;
  EXPECT_EQ(Csv(u, 0, "simulator setting"), io::FormatDouble(np.quantization_urad));
  EXPECT_EQ(Csv(u, 1, "simulator setting"), io::FormatDouble(np.arw_dpsh));
  EXPECT_EQ(Csv(u, 2, "simulator setting"), io::FormatDouble(np.bias_instability_dph));
  EXPECT_EQ(Csv(u, 3, "simulator setting"), io::FormatDouble(np.rrw_dphpsh));
  EXPECT_EQ(Csv(u, 4, "simulator setting"), io::FormatDouble(np.rate_ramp_dphph));
  EXPECT_EQ(Shown(u, 5, "simulator setting"), "-");  // the simulator sets no minimum
  EXPECT_EQ(Csv(u, 1, "noise only (truth)"), io::FormatDouble(0.00458));
  EXPECT_NE(u.title.find("run B"), std::string::npos);
}

TEST(SettingsTable, RowsSayHowTheRunWasSetUp) {
  StudyResult s;
  s.simulated = true;
  s.options.seed = 7;
  s.options.ensemble_size = 12;
  s.options.realisations = 30;
  s.options.causal.window = 64;
  s.options.duration_s = 7200.0;
  s.run_a.samples = 7200;
  s.drift_options.reference_c = 20.0;
  s.threads = 0;
  internal::FillSettingsTable(s);
  const Table& t = s.settings_table;
  EXPECT_EQ(t.header, (std::vector<std::string>{"setting", "value"}));
  EXPECT_EQ(FirstColumn(t), (std::vector<std::string>{
                                "source", "duration, rate", "seed", "decomposition", "selection",
                                "learner", "predict mode", "compensate mode", "threads"}));
  EXPECT_EQ(Csv(t, 1, "value"), "2 h per run at 1 Hz (7200 samples)");
  EXPECT_EQ(Csv(t, 2, "value"), "7 (run A), " + std::to_string(RunBSeed(7)) + " (run B)");
  EXPECT_NE(Csv(t, 3, "value").find("ensemble 12"), std::string::npos);
  EXPECT_NE(Csv(t, 4, "value").find("30 white-noise realisations"), std::string::npos);
  EXPECT_NE(Csv(t, 6, "value").find("causal windows of 64 down to 32 samples (6, ends averaged)"),
            std::string::npos);
  EXPECT_NE(Csv(t, 7, "value").find("equilibrium at 20 degC"), std::string::npos);
  EXPECT_EQ(Csv(t, 8, "value"), "all cores");
  // Text cells are shown as they are written.
  EXPECT_EQ(t.shown, t.csv);

  // A user's log: its columns, rate and length instead of the simulation's duration.
  StudyResult log;
  log.source = "chamber.csv";
  log.target_name = "gyro_x";
  log.unit = "deg/h";
  log.temperature_name = "temp_x";
  log.output = Eigen::VectorXd::Zero(7201);
  log.rate_hz = 2.0;
  log.rate_source = "from time_s";
  log.time_h = Eigen::VectorXd::LinSpaced(7201, 0.0, 1.0);
  log.threads = 2;
  internal::FillSettingsTable(log);
  const Table& u = log.settings_table;
  EXPECT_EQ(FirstColumn(u),
            (std::vector<std::string>{"source", "columns", "samples, rate", "seed", "decomposition",
                                      "selection", "learner", "predict mode", "compensate mode",
                                      "threads"}));
  EXPECT_EQ(Csv(u, 0, "value"), "chamber.csv");
  EXPECT_EQ(Csv(u, 1, "value"), "output gyro_x (deg/h), temperature temp_x");
  EXPECT_EQ(Csv(u, 2, "value"), "7201 samples at 2 Hz (from time_s), 1 h");
  EXPECT_EQ(Csv(u, 3, "value"), "1 (decomposition and learners)");
  EXPECT_NE(Csv(u, 8, "value").find("the fitted intercept"), std::string::npos);
  EXPECT_EQ(Csv(u, 9, "value"), "2");
}

TEST(TimingTable, OneRowPerStageThenTheTotal) {
  StudyResult s;
  s.stage_s = {{"read", 0.012345}, {"decomposition and selection", 3.14159}};
  internal::FillTimingTable(s, 9.87654);
  const Table& t = s.timing_table;
  EXPECT_EQ(t.header, (std::vector<std::string>{"stage", "seconds"}));
  EXPECT_EQ(FirstColumn(t),
            (std::vector<std::string>{"read", "decomposition and selection",
                                      "total until the report (files written after)"}));
  EXPECT_EQ(Csv(t, 1, "seconds"), io::FormatDouble(3.14159));
  EXPECT_EQ(Shown(t, 0, "seconds"), "0.0123");
  EXPECT_EQ(Shown(t, 1, "seconds"), "3.14");
  EXPECT_EQ(Shown(t, 2, "seconds"), "9.88");
}

}  // namespace
}  // namespace gyrodrift::study
