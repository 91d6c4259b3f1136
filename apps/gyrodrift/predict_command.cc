// gyrodrift predict: one-step-ahead (or H-step-ahead) predictions of a saved predict-mode model on
// a CSV log.
#include <fmt/core.h>

#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/predict_task.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct PredictArgs {
  std::string model;
  std::string input;
  std::string output;
  tasks::PredictSettings settings;
  double rate_hz = 0.0;  // --rate-hz: the log's rate where its time_s is wrong; 0 = from time_s
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

void Run(const PredictArgs& a) {
  RequireOutputsAreNotInputs({a.model, a.input}, {a.output, SidecarPath(a.output)});
  a.settings.Validate();  // named as the flags bound to the settings
  const io::LoadedModel loaded = io::ReadModelFile(a.model);
  tasks::RequirePredictMode(loaded, a.model);
  a.log.RequireOneRecord("predict", "a prediction from the output's own past runs across the gaps");
  std::string notes;
  std::vector<bool> logged;
  const io::CsvTable table = ReadLog(a.input, a.log, &notes, nullptr, {}, &logged);
  notes += MadeUpRowsPredictionNote(logged);
  std::string rate_how;
  const double log_hz = io::ResolveSampleRate(table, a.rate_hz, &rate_how);
  tasks::RequirePredictRate(loaded, a.model, a.input, log_hz, rate_how);
  RequireModelColumns(loaded, table);
  const Eigen::VectorXd y = table.Column(loaded.info.target_column);
  Eigen::VectorXd temperature;
  if (loaded.model.uses_temperature()) temperature = table.Column(loaded.info.temperature_column);
  tasks::PredictResult r;
  {
    // Causal prediction decomposes several trailing windows per sample: minutes on a long log.
    const bool windows = a.settings.protocol == "causal" &&
                         drift::UsesDecomposition(loaded.model.options.method);
    ProgressBar progress({1.0}, windows && IsTerminal() && !a.quiet);  // Finish() on every path
    progress.BeginStage(0, "causal windows");
    r = tasks::RunPredict(loaded, y, temperature, a.settings, a.input,
                          [&progress](double fraction, std::string_view) {
                            progress.Update(fraction, "");
                          });
  }
  const Eigen::Index count = y.size() - r.first;
  std::vector<io::CsvColumn> columns;
  columns.push_back({"sample", Eigen::VectorXd::LinSpaced(count, static_cast<double>(r.first + 1),
                                                          static_cast<double>(y.size()))});
  if (table.HasColumn("time_s")) columns.push_back({"time_s", table.Column("time_s").tail(count)});
  columns.push_back({"prediction", r.prediction});
  nlohmann::json sidecar = SidecarHeader("predict");
  sidecar.update(tasks::PredictRecord(r, loaded, a.settings, y.size(), a.model, a.input));
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) {
    fmt::print("{}", notes);
    const int h = a.settings.horizon;
    const std::string ahead = h > 1 ? std::to_string(h) + "-step-ahead, " : "";
    fmt::print("{}\npredicted samples {}..{} ({}{} protocol)\n{}wrote {} and {}\n",
               loaded.model.Summary(), r.first + 1, y.size(), ahead, a.settings.protocol,
               r.window_note.empty() ? "" : r.window_note + "\n", a.output, SidecarPath(a.output));
  }
}

const RegisterCommand kRegister("predict", 60, [](CLI::App& app) {
  auto args = std::make_shared<PredictArgs>();
  CLI::App* cmd = app.add_subcommand(
      "predict",
      "One-step-ahead (or --horizon H steps ahead) predictions of a saved predict-mode model.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift fit train.csv --target rate_dph --mode predict --lags 4 -o model.json\n"
      "  gyrodrift predict model.json test.csv --protocol causal --window 4096 -o pred.csv\n"
      "writes pred.csv with columns sample (1-based row of test.csv), time_s (if test.csv has\n"
      "it) and prediction, one row per predicted sample: rows before the model has its p lags\n"
      "of history (for ms-elm/emd-elm under the causal protocol, 16 samples to decompose), and\n"
      "H-1 more with --horizon H, are left out. causal (default): the sub-series at t come from\n"
      "decomposing only trailing windows y[t-L..t-1], L from W down to W/2 (--windows, their\n"
      "ends averaged; each followed by its last samples reversed, --mirror), what a running\n"
      "system can do. paper:\n"
      "the whole file is decomposed once, so predictions see future samples (the literature's\n"
      "protocol, for comparison only). --horizon H: each prediction of y[t] is made at t-H+1\n"
      "from the samples before it, feeding each sub-model its own predictions for the H-1\n"
      "steps in between (recursive); a model with temperature inputs reads them from the file\n"
      "at every step.\n"
      "pred.csv.json records the options and the model.");
  cmd->add_option("model", args->model, "model file written by 'gyrodrift fit'")
      ->required()
      ->check(kInputFile);
  cmd->add_option("input", args->input, "CSV log with the model's target (and temperature) column")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(cmd->add_option("--protocol", args->settings.protocol, "causal|paper")->capture_default_str(),
              {"protocol"});
  AddCausalWindowOptions(cmd, &args->settings.causal);
  cmd->add_option("--rate-hz", args->rate_hz,
                  "the log's sample rate, Hz, where its time_s does not give it; it must be the "
                  "model's (default: from time_s)")
      ->check(CLI::PositiveNumber);
  BindSetting(
      cmd->add_option("--horizon,-H", args->settings.horizon,
                      "steps ahead: predict y[t] from the samples up to t-H (recursive for H > 1)")
          ->capture_default_str(),
      {"horizon"});
  BindSetting(cmd->add_option("--threads,-j", args->settings.threads, "worker threads (0 = all cores)")
                  ->capture_default_str(),
              {"threads"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
