// The compensate task (tasks/compensate_task.h): the compensated output is the target minus the
// estimate, the figures are over the logged rows, the truth's share is 1 - RMS(truth - estimate) /
// RMS(truth) (undefined for a zero truth), filled gaps are marked or left out, and the refusals
// come before any estimate.
#include "gyrodrift/tasks/compensate_task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/tasks/fit_task.h"
#include "support/test_support.h"

namespace gyrodrift::tasks {
namespace {

const io::LogOptions kFlags{.gaps_name = "--gaps"};

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = test::TempDir("compensate_task") + "/" + name;
  io::WriteFileAtomically(path, text);
  return path;
}

std::vector<io::LoadedModel> Fit(const std::string& path, const std::string& targets,
                                 const std::string& mode = "compensate") {
  const FitRun run = AssembleFitRun({ReadTaskLog(path, kFlags, 0.0)}, targets,
                                    mode == "compensate" ? "temperature_c" : "", kFlags);
  const drift::FitSettings s{.mode = mode,
                             .method = mode == "compensate" ? "thermal" : "elm",
                             .has_temperature = mode == "compensate"};
  return RunFit(run, s, "dph", kFlags).axes;
}

double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / static_cast<double>(v.size())); }

TEST(CompensateTask, TheOutputIsTheTargetMinusTheEstimate) {
  const std::string cal = WriteText("cal.csv", test::ThermalLogCsv(1500, 1));
  const std::vector<io::LoadedModel> axes = Fit(cal, "rate_dph");
  const TaskLog log = ReadTaskLog(WriteText("ver.csv", test::ThermalLogCsv(900, 2)), kFlags);
  const CompensateResult r = RunCompensate(axes, log, kFlags, {.truth = "drift_dph"}, "m.json");
  ASSERT_EQ(r.axes.size(), 1u);
  const AxisCompensation& c = r.axes[0];
  const Eigen::VectorXd y = log.table.Column("rate_dph"), truth = log.table.Column("drift_dph");
  EXPECT_EQ(c.compensated, (y - c.estimate).eval());
  EXPECT_DOUBLE_EQ(c.truth_removed, 1.0 - Rms(truth - c.estimate) / Rms(truth));
  EXPECT_EQ(c.summary.samples, 900);
  // The log's columns, then drift_est, drift_sd (an identified model), compensated.
  ASSERT_EQ(r.columns.size(), 7u);
  EXPECT_EQ(r.columns[4].name, "drift_est");
  EXPECT_EQ(r.columns[5].name, "drift_sd");
  EXPECT_EQ(r.columns[6].name, "compensated");
  EXPECT_EQ(r.record["truth"]["removed_percent"].get<double>(), 100.0 * c.truth_removed);
  EXPECT_EQ(r.record["options"]["records"].get<int>(), 1);
  // A zero truth has no share to remove.
  const AxisCompensation zero = CompensateAxis(axes[0], y, log.table.Column("temperature_c"), {},
                                               {}, Eigen::VectorXd::Zero(y.size()));
  EXPECT_TRUE(std::isnan(zero.truth_removed));
  EXPECT_THROW(CompensateAxis(axes[0], y, log.table.Column("temperature_c"), {}, {}, {},
                              {.drift_window_s = 0.0}),
               OptionError);
}

TEST(CompensateTask, FilledGapsAreMarkedOrLeftOut) {
  const std::string cal = WriteText("cal2.csv", test::ThermalLogCsv(1500, 3));
  const std::vector<io::LoadedModel> axes = Fit(cal, "rate_dph");
  // Rows 300..309 missing: a gap of 11 s.
  std::string text = test::ThermalLogCsv(800, 4), kept;
  size_t line = 0, start = 0;
  for (size_t end = text.find('\n'); end != std::string::npos; end = text.find('\n', start)) {
    if (line < 301 || line > 310) kept += text.substr(start, end - start + 1);
    start = end + 1;
    ++line;
  }
  const std::string path = WriteText("gap.csv", kept);
  const io::LogOptions interpolate{.gaps = io::GapPolicy::kInterpolate, .gaps_name = "--gaps"};
  const CompensateResult i =
      RunCompensate(axes, ReadTaskLog(path, interpolate), interpolate, {}, "m.json");
  ASSERT_EQ(i.columns[4].name, "interpolated");
  EXPECT_EQ(i.columns[4].values.sum(), 10.0);
  EXPECT_EQ(i.columns[0].values.size(), 800);
  EXPECT_EQ(i.axes[0].summary.samples, 790);  // the figures: logged rows only
  const io::LogOptions carry{.gaps = io::GapPolicy::kCarry, .gaps_name = "--gaps"};
  const CompensateResult c = RunCompensate(axes, ReadTaskLog(path, carry), carry, {}, "m.json");
  EXPECT_EQ(c.columns[0].values.size(), 790);
  EXPECT_EQ(c.record["rows"]["written"].get<int>(), 790);
}

TEST(CompensateTask, RefusalsComeBeforeAnyEstimate) {
  const std::string cal = WriteText("cal3.csv", test::ThermalLogCsv(1500, 5));
  const TaskLog log = ReadTaskLog(cal, kFlags);
  EXPECT_THROW(RunCompensate(Fit(cal, "rate_dph", "predict"), log, kFlags, {}, "p.json"),
               UsageError);
  EXPECT_THROW(RunCompensate(Fit(cal, "rate_dph,drift_dph"), log, kFlags,
                             {.truth = "drift_dph"}, "m.json"),
               UsageError);
  const std::vector<io::LoadedModel> axes = Fit(cal, "rate_dph");
  const CompensateResult once = RunCompensate(axes, log, kFlags, {}, "m.json");
  const std::string out = WriteText("out.csv", io::RenderCsv(once.columns));
  try {
    RunCompensate(axes, ReadTaskLog(out, kFlags), kFlags, {}, "m.json");
    FAIL() << "a compensated log was compensated again";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("already has a column 'drift_est'"), std::string::npos);
  }
  io::LoadedModel other = axes[0];
  other.info.temperature_column = "case_c";
  EXPECT_THROW(CompensateWarnings({other}, log, kFlags), DataError);
}

// A log at another rate than the model's would run its lags that many times too fast: refused
// where time_s says so, run where nothing states the log's rate.
TEST(CompensateTask, RefusesALogAtAnotherSampleRate) {
  const std::string cal = WriteText("cal_rate.csv", test::ThermalLogCsv(1500, 5));
  const std::vector<io::LoadedModel> axes = Fit(cal, "rate_dph");
  const io::CsvTable ver = io::CsvTable::Parse(test::ThermalLogCsv(600, 6), "ver");
  std::vector<io::CsvColumn> columns;
  for (const std::string& name : ver.header()) {
    Eigen::VectorXd v = ver.Column(name);
    if (name == "time_s") v *= 0.1;  // 10 Hz
    columns.push_back({name, v});
  }
  const std::string fast = WriteText("fast.csv", io::RenderCsv(columns));
  try {
    RunCompensate(axes, ReadTaskLog(fast, kFlags), kFlags, {}, "m.json");
    FAIL() << "a 10 Hz log ran through a 1 Hz model";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "fast.csv is sampled at 10 Hz (from the steps of time_s), m.json was "
                  "fitted at 1 Hz: its thermal lags and temperature rates would run 10 times too "
                  "fast (resample the log to 1 Hz or fit the model on a log at 10 Hz; give "
                  "--rate-hz if time_s is wrong)"),
              std::string::npos)
        << e.what();
  }
  // The rate stated (time_s is wrong, as fit --rate-hz says): compensated at it.
  EXPECT_EQ(RunCompensate(axes, ReadTaskLog(fast, kFlags), kFlags, {.rate_hz = 1.0}, "m.json")
                .axes.size(),
            1u);
  columns.erase(columns.begin());  // no time_s: the rate is the model's
  const std::string untimed = WriteText("untimed.csv", io::RenderCsv(columns));
  EXPECT_EQ(RunCompensate(axes, ReadTaskLog(untimed, kFlags), kFlags, {}, "m.json").axes.size(),
            1u);
}

}  // namespace
}  // namespace gyrodrift::tasks
