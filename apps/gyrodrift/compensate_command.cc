// gyrodrift compensate: remove the drift a saved compensate-mode model estimates from temperature.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/compensate_task.h"

namespace gyrodrift::cli {
namespace {

struct CompensateArgs {
  std::string model;
  std::string input;
  std::string output;
  tasks::CompensateSettings settings;  // --truth, --drift-window-s, --rate-hz
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

void Run(const CompensateArgs& a) {
  RequireOutputsAreNotInputs({a.model, a.input}, {a.output, SidecarPath(a.output)});
  const std::vector<io::LoadedModel> axes = io::ReadModelFileAxes(a.model);
  tasks::RequireCompensateMode(axes, a.model);
  const io::LogOptions log_options = a.log.Options();
  const tasks::TaskLog log = tasks::ReadTaskLog(a.input, log_options);
  // Before the work: a temperature that does not look like degC (each column once).
  const std::vector<std::string> warnings = tasks::CompensateWarnings(axes, log, log_options);
  if (!a.quiet) {
    for (const std::string& w : warnings) fmt::print("warning: {}\n", w);
  }
  const tasks::CompensateResult r =
      tasks::RunCompensate(axes, log, log_options, a.settings, a.model);
  nlohmann::json sidecar = SidecarHeader("compensate");
  sidecar.update(r.record);
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(r.columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) fmt::print("{}wrote {} and {}\n", r.text, a.output, SidecarPath(a.output));
}

const RegisterCommand kRegister("compensate", 70, [](CLI::App& app) {
  auto args = std::make_shared<CompensateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compensate", "Subtract the drift a saved compensate-mode model estimates from temperature.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift fit train.csv --target rate_dph --temperature temperature_c --mode compensate "
      "\\\n"
      "      -o model.json\n"
      "  gyrodrift compensate model.json test.csv -o out.csv\n"
      "writes out.csv: every column of test.csv, then drift_est (the model's drift estimate,\n"
      "from the temperature history only), drift_sd (its standard deviation, for identified\n"
      "models: thermal, ms-elm, emd-elm) and compensated (= target column - drift_est), one\n"
      "row per input row; out.csv.json records the model and the std before and after.\n"
      "A model of several axes (fit --target gyro_x,gyro_y,gyro_z) adds drift_est_<target>,\n"
      "drift_sd_<target> and compensated_<target> for each.\n"
      "With --truth drift_dph (a simulated log) it also reports how much of the true drift's\n"
      "RMS the estimate removes: 1 - RMS(truth - drift_est) / RMS(truth).\n"
      "test.csv needs the columns the model was trained with (here rate_dph and temperature_c).\n"
      "A log with gaps: --gaps interpolate fills them and marks the made-up rows in a column\n"
      "interpolated (1 = made up); --gaps carry runs the estimate across them on the interpolated\n"
      "temperature and writes the logged rows only. Either way the std and the truth share are\n"
      "over the logged rows.");
  cmd->add_option("model", args->model, "model file written by 'gyrodrift fit --mode compensate'")
      ->required()
      ->check(kInputFile);
  cmd->add_option("input", args->input, "CSV log with the model's target and temperature columns")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(cmd->add_option("--drift-window-s", args->settings.drift_window_s,
                              "length of the blocks whose means give the slow variation before and "
                              "after, s (the fleet manifest's drift_window_s)")
                  ->capture_default_str(),
              {"drift_window_s"});
  BindSetting(cmd->add_option("--rate-hz", args->settings.rate_hz,
                              "the log's sample rate, Hz, where its time_s does not give it (as "
                              "fit --rate-hz); it must be the model's (default: from time_s)")
                  // 0 is the settings' "not given": typed, it is a rate out of range.
                  ->check(CLI::Validator(
                      [](std::string& value) {
                        return std::strtod(value.c_str(), nullptr) == 0.0
                                   ? std::string(
                                         "0 is no sample rate (leave the flag out to read "
                                         "it from time_s)")
                                   : std::string();
                      },
                      "", "NONZERO")),
              {"rate_hz"});
  cmd->add_option("--truth", args->settings.truth,
                  "column of the true drift (e.g. the simulator's drift_dph): also report the "
                  "share of its RMS the estimate removes");
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
