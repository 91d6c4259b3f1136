// The `fit` user operation, written once for every front end (issue 25): the calibration run
// assembled from one or several logs (records of one run), the checks a run must pass for the
// chosen method, one drift model per target column fitted with the same settings, and the record
// the model file holds. `gyrodrift fit`, the Python package's DriftModel.fit and the fleet's
// calibration (`gyrodrift calibrate`, one unit's axes) call these and nothing below them.
//
// Settings: drift::FitSettings (fit_settings.h), their one mapping onto DriftOptions.
// Cost: drift::FitDriftModel's, once per target.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/drift/records.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::tasks {

// The run a fit learns from: the target columns, then the temperature columns, of every log one
// after the other, as records of one run (drift::RecordRows).
struct FitRun {
  std::vector<std::string> targets = {};  // column names: one model per target
  std::vector<std::string> temperatures = {};  // column names, the same for every target; may be empty
  drift::RecordRows rows = {};
  double rate_hz = 0.0;  // of the logs; 0 = the settings' rate_hz (arrays without a time axis)
  std::string rate_how = {};  // how the first log's rate was settled (TaskLog::rate_how)
  std::string source = {};    // the logs, comma-separated (informative, kept in the model file)
  std::string ulog = {};      // the first log that is a PX4 ULog (io::IsUlogFile), or ""
  size_t logs = 1;       // how many logs were appended (messages)
  std::string temperature_spec = {};  // the temperature columns as the user gave them (messages)
};

// The run of `logs` (read by ReadTaskLog; at least one): the columns of `target` and
// `temperature` ("" = none; names or 1-based indices, comma-separated, resolved in each log and
// named `target_option` / `temperature_option` in messages), the logs' records, and the logged
// rows under gaps carry only (interpolate fits on the made-up rows as data). Throws DataError when
// the logs' sample rates differ (io::RequireSameSampleRate), UsageError for a bad column.
FitRun AssembleFitRun(const std::vector<TaskLog>& logs, const std::string& target,
                      const std::string& temperature, const io::LogOptions& log,
                      const std::string& target_option = "--target",
                      const std::string& temperature_option = "--temperature");

// What a fit made: one model per target, with the columns and the source it was fitted on.
struct FitResult {
  std::vector<io::LoadedModel> axes;
  drift::DriftOptions options;  // as fitted (the run's sample rate)
  // The record: the model file's text (io::RenderModelFile), what `fit -o` and the fleet write.
  std::string ModelFile() const;
};

// Reports `axis` (0-based), the fraction of its fit done and the step (from the fit's threads);
// called with fraction 0 and an empty step when the axis starts.
using FitProgress = std::function<void(int axis, double fraction, std::string_view step)>;

// Fits every target of `run` with `settings` (rate_hz: the run's when it has one; threads: of
// each fit), recording `rate_unit` (dph | dps | rads) in each model. Throws what
// drift::FitSettings::Validate throws; UsageError naming the setting as `log` spells it when a
// temperature column is also a target, when several records meet a method other than thermal, or
// the logged rows (gaps carry) meet a method or mode that cannot keep to them. These checks run
// before any fit.
FitResult RunFit(const FitRun& run, const drift::FitSettings& settings,
                 const std::string& rate_unit, const io::LogOptions& log = {},
                 const FitProgress& progress = {});

// The run's checks of RunFit alone, for a caller that must refuse before other work.
void CheckFitRun(const FitRun& run, const drift::DriftOptions& options, const io::LogOptions& log);

}  // namespace gyrodrift::tasks
