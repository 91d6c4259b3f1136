// The fit task (tasks/fit_task.h): logs assembled as records of one run, the run's checks spelt as
// the caller's user types them, and a fit equal to the library's (the model file the CLI, Python
// and the fleet write is tasks::RunFit's).
#include "gyrodrift/tasks/fit_task.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::tasks {
namespace {

const io::LogOptions kFlags{.gaps_name = "--gaps"};

// test::TempDir empties the test's folder: each log is read before the next is written, or the
// logs share one folder (`dir`).
std::string WriteLog(const std::string& name, int n, std::uint64_t seed, double step_s = 1.0,
                     std::string dir = "") {
  if (dir.empty()) dir = test::TempDir("fit_task");
  const std::string path = dir + "/" + name;
  io::WriteFileAtomically(path, test::ThermalLogCsv(n, seed, step_s));
  return path;
}

drift::FitSettings Compensate(std::string method = "thermal") {
  return {.mode = "compensate", .method = std::move(method), .has_temperature = true};
}

TEST(FitTask, LogsAreAppendedAsRecordsOfOneRun) {
  const std::vector<TaskLog> logs = {ReadTaskLog(WriteLog("a.csv", 600, 1), kFlags, 0.0),
                                     ReadTaskLog(WriteLog("b.csv", 400, 2), kFlags, 0.0)};
  // Columns by name or 1-based index, resolved in each log.
  const FitRun run = AssembleFitRun(logs, "2", "temperature_c", kFlags);
  EXPECT_EQ(run.targets, std::vector<std::string>{"rate_dph"});
  EXPECT_EQ(run.temperatures, std::vector<std::string>{"temperature_c"});
  ASSERT_EQ(run.rows.rows.rows(), 1000);
  ASSERT_EQ(run.rows.rows.cols(), 2);
  EXPECT_EQ(run.rows.record_starts, std::vector<Eigen::Index>{600});
  EXPECT_EQ(run.rows.rows(650, 1), logs[1].table.Column("temperature_c")[50]);
  EXPECT_EQ(run.rate_hz, 1.0);
  EXPECT_EQ(run.rate_how, "time_s");
  EXPECT_EQ(run.source, logs[0].path + "," + logs[1].path);
  EXPECT_EQ(run.logs, 2u);
}

TEST(FitTask, LogsOfDifferentRatesAreRefused) {
  const std::vector<TaskLog> logs = {ReadTaskLog(WriteLog("r1.csv", 300, 1), kFlags, 0.0),
                                     ReadTaskLog(WriteLog("r2.csv", 300, 2, 2.0), kFlags, 0.0)};
  EXPECT_THROW(AssembleFitRun(logs, "rate_dph", "temperature_c", kFlags), DataError);
}

TEST(FitTask, TheFitIsTheLibrarysAndItsRecordTheModelFile) {
  const std::vector<TaskLog> logs = {ReadTaskLog(WriteLog("f.csv", 1200, 3), kFlags, 0.0)};
  const FitRun run = AssembleFitRun(logs, "rate_dph,drift_dph", "temperature_c", kFlags);
  std::vector<int> started;
  const FitResult fit = RunFit(run, Compensate(), "dps", kFlags,
                               [&](int axis, double fraction, std::string_view step) {
                                 if (step.empty()) started.push_back(axis);
                                 EXPECT_GE(fraction, 0.0);
                               });
  EXPECT_EQ(started, (std::vector<int>{0, 1}));
  ASSERT_EQ(fit.axes.size(), 2u);
  drift::DriftOptions o = drift::MakeDriftOptions(Compensate());
  o.features.rate_hz = 1.0;
  EXPECT_EQ(fit.options, o);
  const drift::DriftModel direct = drift::FitDriftModel(
      logs[0].table.Column("drift_dph"), logs[0].table.Column("temperature_c"), o, {}, {});
  const io::ModelFileInfo info{"drift_dph", "temperature_c", logs[0].path, "", "dps"};
  EXPECT_EQ(io::RenderModelFile({fit.axes[1]}), io::RenderModelFile(direct, info));
  EXPECT_EQ(fit.ModelFile(), io::RenderModelFile(fit.axes));
  EXPECT_EQ(fit.axes[0].info.target_column, "rate_dph");
}

TEST(FitTask, TheRunsChecksNameTheSettingAsTheUserTypesIt) {
  const std::string dir = test::TempDir("fit_task");
  const std::string a = WriteLog("c1.csv", 300, 1, 1.0, dir), b = WriteLog("c2.csv", 300, 2, 1.0, dir);
  const io::LogOptions keys{};
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const FitRun same = AssembleFitRun({ReadTaskLog(a, kFlags, 0.0)}, "rate_dph", "rate_dph", kFlags);
  EXPECT_EQ(message([&] { RunFit(same, Compensate(), "dph", kFlags); }),
            "--temperature = rate_dph: must differ from --target");
  EXPECT_EQ(message([&] { RunFit(same, Compensate(), "dph", keys); }),
            "temperature = rate_dph: must differ from the target");
  // A run made of arrays (Python's) names its columns without a spec: the names stand for it.
  FitRun twice = AssembleFitRun({ReadTaskLog(a, kFlags, 0.0)}, "rate_dph", "temperature_c", keys);
  twice.temperature_spec.clear();
  twice.temperatures = {"temperature_c", "temperature_c"};
  EXPECT_EQ(message([&] { RunFit(twice, Compensate(), "dph", keys); }),
            "temperature = 'temperature_c,temperature_c': must be a list without repeats");
  twice.temperatures = {"rate_dph"};
  EXPECT_EQ(message([&] { RunFit(twice, Compensate(), "dph", keys); }),
            "temperature = rate_dph: must differ from the target");
  const std::vector<TaskLog> two = {ReadTaskLog(a, kFlags, 0.0), ReadTaskLog(b, kFlags, 0.0)};
  const FitRun records = AssembleFitRun(two, "rate_dph", "temperature_c", kFlags);
  EXPECT_NE(message([&] { RunFit(records, Compensate("poly"), "dph", kFlags); })
                .find("--method poly: several records (several input logs) are fitted by "
                      "--method thermal only"),
            std::string::npos);
  EXPECT_NE(message([&] { RunFit(records, Compensate("poly"), "dph", keys); })
                .find("method = 'poly': several records (several calibration logs)"),
            std::string::npos);
  // Carry: only the logged rows may be fitted, which a decomposition cannot do.
  FitRun carry = AssembleFitRun({two[0]}, "rate_dph", "temperature_c", kFlags);
  carry.rows.logged.assign(300, true);
  carry.rows.logged[7] = false;
  EXPECT_NE(message([&] { RunFit(carry, Compensate("ms-elm"), "dph", kFlags); })
                .find("--gaps carry: the fit uses the logged rows only"),
            std::string::npos);
  // Option errors come from the settings, naming the setting.
  drift::FitSettings bad = Compensate();
  bad.ensemble = 0;
  EXPECT_THROW(bad.Validate(), OptionError);
  EXPECT_THROW(RunFit(same, bad, "dph", kFlags), OptionError);
}

}  // namespace
}  // namespace gyrodrift::tasks
