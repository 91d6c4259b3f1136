// A gyro log as the drift tasks read it (fit, compensate, evaluate; the fleet's calibration and
// verification logs): the table under the log settings, where its records start, which rows were
// logged, its sample rate and what the user must hear about it. One home for the rules
// `gyrodrift fit` / `compensate` / `evaluate` and `gyrodrift calibrate` share (issue 25).
//
// Messages spell a setting as the caller's user types it: flags (--rate-hz, --target) when the log
// settings' gaps_name is a flag ("--gaps"), else keys (rate_hz, target), as io::SpellGaps does.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/gyro_log.h"

namespace gyrodrift::tasks {

struct TaskLog {
  std::string path;
  io::CsvTable table;
  std::vector<Eigen::Index> record_starts;  // gaps split: the first row of every later record
  std::vector<bool> logged;  // gaps interpolate or carry: one flag per row, true where logged
  double rate_hz = 0.0;
  std::string rate_how;  // "given", "time_s" or "default" (io::ResolveSampleRate)
  std::string gap_note;   // io::ReadLog's note on filled or split gaps and skipped lines, or ""
  std::string time_note;  // io::NonUniformTimeNote, or ""
};

// Reads `path` under `log` (io::ReadLog, record starts and the logged mask always asked for) and
// settles its sample rate: `rate_hz_given` when > 0, else from time_s, else 1 Hz
// (io::ResolveSampleRate). Without a rate (a task that takes none, such as compensate: the
// model's), rate_hz stays 0 and rate_how "".
TaskLog ReadTaskLog(const std::string& path, const io::LogOptions& log, double rate_hz_given);
TaskLog ReadTaskLog(const std::string& path, const io::LogOptions& log);

// True when the caller's user spells settings as flags (log.gaps_name "--gaps").
bool SpeltAsFlags(const io::LogOptions& log);

// Where io::ResolveSampleRate's rate came from (`how` "given", "time_s" or "default"), as the
// user reads it beside the rate: "given by --rate-hz" (`flags`) or "given by rate_hz", ...
std::string RateSourceText(const std::string& how, bool flags);

// DataError naming the log and the model when the log's rate (`log_hz`, from `how`; "default", a
// rate nobody stated, is not checked) is more than 1 % off the model's `model_hz`: `effect` says
// what the model's sample-counted parts would do at ratio = log_hz / model_hz ("its lags would
// run 10 times too fast"). The advice to give the rate is offered where time_s gave it.
void RequireRateOfModel(const std::string& log_path, double log_hz, const std::string& how,
                        bool flags, const std::string& model_path, double model_hz,
                        const std::function<std::string(double ratio)>& effect);

// The columns of `spec` ("a" or "a,b", names or 1-based indices): their names, the names joined by
// commas, and the N x C matrix. Throws UsageError naming `option` (--target, target) for an
// unknown, empty or repeated column.
struct SelectedColumns {
  std::vector<std::string> names;
  std::string joined;
  Eigen::MatrixXd values;
};
SelectedColumns ReadColumns(const io::CsvTable& table, const std::string& spec,
                            const std::string& option);

// The comma-separated names of a model file's temperature_column ("" gives one empty name).
std::vector<std::string> SplitColumns(const std::string& names);

// Who reads a message about a log, and so how it names the file and a setting: the CLI's user
// (the path as typed, --rate-hz), a manifest's (the file's name, rate_hz in the manifest) or
// Python's (the path as given, the keyword rate_hz=).
enum class Audience { kFlags, kManifest, kKeywords };

// What the user must know about a log before the work: its sample rate assumed (rate_how
// "default"; "" = the task takes no rate) and each `temperature_columns` that does not look like
// degC (drift::TemperatureWarning). One line each, without "warning: ": for flags
// "PATH has no time_s column: ... (give --rate-hz if it is not)", for a manifest
// "FILE: no time_s column: ... (set rate_hz in the manifest if it is not)".
std::vector<std::string> LogWarnings(const TaskLog& log, const std::string& rate_how,
                                     const std::vector<std::string>& temperature_columns,
                                     Audience audience);

}  // namespace gyrodrift::tasks
