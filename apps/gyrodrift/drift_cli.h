// Option plumbing shared by the drift-model subcommands (fit, predict, compensate, evaluate): the
// model options fit and evaluate take, the given sample rate, and the column checks a saved model
// needs.
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
// --target, --temperature, --reference-temperature, --nonlinear, --hysteresis,
// --standard-errors, --mode, --decomposition, --lags, --hidden, --rate-hz, --thermal-features,
// --time-constants, --ensemble, --realisations, --seed, --threads, the log options
// (AddLogOptions) and --quiet to cmd, each flag bound to its drift::FitSettings setting.
void AddDriftOptions(CLI::App* cmd, DriftArgs* args, bool split_records);

// Adds --window (-W), --mirror, --windows and --causal-ensemble to cmd, each bound to its field
// of `causal` (BindSetting: a refusal of causal.window names --window), under the help group
// `group` when one is given (the demo's "Advanced").
void AddCausalWindowOptions(CLI::App* cmd, drift::CausalOptions* causal,
                            const std::string& group = "");

// The settings of the arguments with `method` ("auto" or a method name), before any file is
// read (drift::MakeDriftOptions maps them; the sample rate is settled later by
// tasks::ReadTaskLog, given GivenRateHz).
drift::FitSettings Settings(const DriftArgs& args, const std::string& method);

// --rate-hz if given, else 0 (tasks::ReadTaskLog then reads the rate from time_s, or takes 1 Hz).
double GivenRateHz(const DriftArgs& args);

using tasks::RequireModelColumns;

using tasks::ReadColumns;
using tasks::SelectedColumns;
using tasks::SplitColumns;

}  // namespace gyrodrift::cli
