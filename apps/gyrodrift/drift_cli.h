// Option plumbing shared by the drift-model subcommands (fit, predict, compensate, evaluate): the
// model options fit and evaluate take, the sample-rate rule, the column checks a saved model
// needs, and the terminal progress line.
#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/compensate_task.h"
#include "gyrodrift/tasks/task_log.h"
#include "cli_util.h"

namespace gyrodrift::cli {

// Options fit and evaluate share.
struct DriftArgs {
  std::vector<std::string> inputs;  // fit takes several calibration logs, evaluate one
  std::string target;
  std::string temperature;  // "" = none; several columns comma-separated
  // The model settings the flags set (drift::MakeDriftOptions maps them); the method, the
  // reference temperature and whether there is a temperature are settled by Settings().
  drift::FitSettings settings;
  double reference_c = 0.0;
  CLI::Option* reference_option = nullptr;  // to tell "--reference-temperature given"
  CLI::Option* rate_option = nullptr;       // ... "--rate-hz given" from the default
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

// Adds the input(s) (several with `split_records`: fit's calibration logs),
// --target, --temperature, --reference-temperature, --nonlinear, --hysteresis, --mode,
// --decomposition, --lags, --hidden, --rate-hz, --thermal-features, --time-constants,
// --ensemble, --realisations, --seed, --threads, --gaps, --delimiter and --quiet to cmd, each
// flag bound to its drift::FitSettings setting.
void AddDriftOptions(CLI::App* cmd, DriftArgs* args, bool split_records);

// The settings of the arguments with `method` ("auto" or a method name), before any file is
// read (drift::MakeDriftOptions maps them; the sample rate is settled later by ResolveRateHz).
drift::FitSettings Settings(const DriftArgs& args, const std::string& method);

// --rate-hz if given; else 1 / (median step of a `time_s` column) if the file has one; else 1.
// `how` receives "given", "time_s" or "default". Throws DataError on a time_s column whose
// median step is not positive.
double ResolveRateHz(const DriftArgs& args, const io::CsvTable& table, std::string* how);

// The warnings to print before the work on a log `path`: its sample rate assumed (`rate_how` as
// ResolveRateHz returns it, "default"; "" = the command takes no rate) and each of its
// `temperature_columns` that does not look like degC (drift::TemperatureWarning). Each line
// "warning: ...\n"; "" when there is nothing to say.
std::string InputWarnings(const std::string& path, const std::string& rate_how,
                          const io::CsvTable& table,
                          const std::vector<std::string>& temperature_columns);

using tasks::RequireModelColumns;

using tasks::ReadColumns;
using tasks::SelectedColumns;
using tasks::SplitColumns;

}  // namespace gyrodrift::cli
