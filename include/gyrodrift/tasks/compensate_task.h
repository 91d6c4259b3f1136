// The `compensate` user operation, written once for every front end (issue 25): a saved
// compensate-mode model's drift estimate (with its standard deviation for identified models)
// subtracted from a log, the figures before and after, the share of a known true drift removed,
// where the estimate extrapolates, and the records the output CSV and its sidecar hold.
// `gyrodrift compensate`, the Python package's DriftModel.estimate / compensate /
// compensation_summary and the fleet's verification (`gyrodrift calibrate`) call these and nothing
// below them.
//
// Units: the model's rate unit; temperatures degC. Cost: drift::EstimateDriftWithSd's.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::tasks {

struct CompensateSettings {
  std::string truth = "";  // column of the true drift (the simulator's drift_dph); "" = none
  // The log's sample rate, Hz, where its time_s does not give it (0: from time_s, else the
  // model's): RequireModelRate checks it against the model's; it times the figures'
  // slow-variation blocks.
  double rate_hz = 0.0;
  // Length of those blocks, s (the fleet's drift_window_s).
  double drift_window_s = drift::kSlowVariationBlockS;
  // Throws OptionError naming the field (rate_hz: 0 or in [1e-9, 1e9]; drift_window_s in
  // [1e-3, 1e9]).
  void Validate() const;
};

// One axis compensated. The estimate runs over every row (the thermal states across filled gaps);
// the figures use the logged rows only.
struct AxisCompensation {
  Eigen::VectorXd estimate, sd, compensated;  // every row; sd: of identified models, else 0
  bool identified = false;                    // the model gives each estimate its sd
  drift::CompensationSummary summary;         // logged rows
  bool has_truth = false;
  double truth_rms = 0.0, residual_rms = 0.0;
  // 1 - RMS(truth - estimate) / RMS(truth), RMS about zero; NaN when the truth is zero.
  double truth_removed = std::numeric_limits<double>::quiet_NaN();
  double outside_share = 0.0;  // logged rows beyond the model's training temperature range
  double drift_sd_mean = std::numeric_limits<double>::quiet_NaN();  // logged rows, identified
  // The output columns of this axis, named with `suffix` ("" or "_<target>"): drift_est,
  // drift_sd (identified models), compensated.
  std::vector<io::CsvColumn> Columns(const std::string& suffix) const;
};

// The axis `loaded` compensates in y (its target) from `temperature` (one column per channel of
// the model), records restarting at `record_starts`, the figures over the `logged` rows (empty =
// every row) against `truth` (empty = none). Throws what drift::EstimateDriftWithSd throws.
AxisCompensation CompensateAxis(const io::LoadedModel& loaded, const Eigen::VectorXd& y,
                                const Eigen::MatrixXd& temperature,
                                const std::vector<Eigen::Index>& record_starts,
                                const std::vector<bool>& logged, const Eigen::VectorXd& truth,
                                const CompensateSettings& settings = {});

// A log compensated by every axis of a model file.
struct CompensateResult {
  std::vector<AxisCompensation> axes;
  std::vector<io::CsvColumn> columns;  // the output CSV: the log's, then each axis's
  nlohmann::json record;               // the sidecar, but for its header (options included)
  std::string text;                    // the console report, the log's gap note first
};

// DataError naming the log and the model when the log's sample rate (`log_hz`, from
// io::ResolveSampleRate with `how`; "default", a rate nobody stated, is not checked) differs from a
// model's by more than 1 %: the model's thermal lags and temperature rates would run that many
// times too fast or slow, silently. `flags`: the rate's source spelt as flags (--rate-hz).
void RequireModelRate(const std::vector<io::LoadedModel>& axes, const std::string& model_path,
                      const std::string& log_path, double log_hz, const std::string& how,
                      bool flags);

// UsageError naming `model_path` unless every axis is a compensate-mode model.
void RequireCompensateMode(const std::vector<io::LoadedModel>& axes,
                           const std::string& model_path);

// What to print before the work on `log`: its temperature columns that do not look like degC
// (LogWarnings, each column once). Throws RequireModelColumns' DataError first.
std::vector<std::string> CompensateWarnings(const std::vector<io::LoadedModel>& axes,
                                            const TaskLog& log, const io::LogOptions& log_options);

// Compensates `log` (read by ReadTaskLog under `log_options`) with `axes` (a model file's, read
// from `model_path`). Refuses, before any estimate (UsageError / DataError naming the file): a
// predict-mode model, a log without the model's columns, a log that has an output column
// already, several axes with a truth column. Filled gaps: interpolate marks the made-up rows in a
// column `interpolated`, carry writes the logged rows only; the figures are over the logged rows.
CompensateResult RunCompensate(const std::vector<io::LoadedModel>& axes, const TaskLog& log,
                               const io::LogOptions& log_options,
                               const CompensateSettings& settings,
                               const std::string& model_path);

// Throws DataError "model needs column 'X' (trained with --target X); IN.csv has: a, b" unless
// the table has the model's target column and, when the model uses it, its temperature columns.
void RequireModelColumns(const io::LoadedModel& loaded, const io::CsvTable& table);

}  // namespace gyrodrift::tasks
