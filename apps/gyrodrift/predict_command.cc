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
#include "gyrodrift/io/model_file.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct PredictArgs {
  std::string model;
  std::string input;
  std::string output;
  std::string protocol = "causal";
  int window = drift::CausalOptions{}.window;
  int horizon = 1;
  int threads = 0;
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

void Run(const PredictArgs& a) {
  RequireOutputsAreNotInputs({a.model, a.input}, {a.output, SidecarPath(a.output)});
  const drift::Protocol protocol = drift::ProtocolFromString(a.protocol);
  if (a.window < 16 || a.window > 1000000) {
    ThrowOption("--window", std::to_string(a.window), "an integer in [16, 1000000]");
  }
  ValidateThreads(a.threads);  // named as --threads, the flag bound to it
  const io::LoadedModel loaded = io::ReadModelFile(a.model);
  const drift::DriftModel& model = loaded.model;
  if (model.options.mode != drift::Mode::kPredict) {
    throw UsageError(a.model +
                     " is a compensate-mode model: use 'gyrodrift compensate' (predict "
                     "needs a model fitted with --mode predict)");
  }

  a.log.RequireOneRecord("predict", "a prediction from the output's own past runs across the gaps");
  std::string notes;
  const io::CsvTable table = ReadLog(a.input, a.log, &notes);
  RequireModelColumns(loaded, table);
  const Eigen::VectorXd y = table.Column(loaded.info.target_column);
  Eigen::VectorXd temperature;
  if (model.uses_temperature()) temperature = table.Column(loaded.info.temperature_column);
  const bool decomposes = drift::UsesDecomposition(model.options.method);
  const Eigen::Index first = drift::FirstPredictable(model, protocol, a.horizon);
  if (y.size() <= first) {
    throw DataError(a.input + " has " + std::to_string(y.size()) +
                    " samples: the model needs more than " + std::to_string(first) +
                    " (its history) to predict any");
  }
  drift::CausalOptions causal;
  causal.window = a.window;
  Execution execution{.threads = a.threads};  // it never changes the result
  Eigen::VectorXd prediction;
  {
    // Causal prediction decomposes one trailing window per sample: minutes on a long log.
    const bool windows = protocol == drift::Protocol::kCausal && decomposes;
    ProgressBar progress({1.0}, windows && IsTerminal() && !a.quiet);  // Finish() on every path
    progress.BeginStage(0, "causal windows");
    execution.progress = [&progress](double fraction, std::string_view) {
      progress.Update(fraction, "");
    };
    prediction =
        drift::PredictAhead(model, y, temperature, first, a.horizon, protocol, causal, execution);
  }

  const Eigen::Index count = y.size() - first;
  std::vector<io::CsvColumn> columns;
  columns.push_back({"sample", Eigen::VectorXd::LinSpaced(count, static_cast<double>(first + 1),
                                                          static_cast<double>(y.size()))});
  if (table.HasColumn("time_s")) columns.push_back({"time_s", table.Column("time_s").tail(count)});
  columns.push_back({"prediction", prediction});

  nlohmann::json sidecar = SidecarHeader("predict");
  sidecar["options"] = {{"model", a.model},   {"input", a.input},     {"protocol", a.protocol},
                        {"window", a.window}, {"horizon", a.horizon}, {"threads", a.threads}};
  sidecar["model"] = {{"summary", model.Summary()},
                      {"method", drift::ToString(model.options.method)},
                      {"target_column", loaded.info.target_column},
                      {"temperature_column", loaded.info.temperature_column},
                      {"lags", model.lags},
                      {"seed", model.options.seed},
                      {"tool_version", loaded.info.tool_version}};
  const std::string window_note =
      protocol == drift::Protocol::kCausal ? drift::CausalWindowNote(model, a.window) : "";
  sidecar["notes"] =
      window_note.empty() ? nlohmann::json::array() : nlohmann::json::array({window_note});
  sidecar["samples"] = y.size();
  sidecar["first_predicted_sample"] = first + 1;
  sidecar["predicted"] = count;
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) {
    fmt::print("{}", notes);
    const std::string ahead = a.horizon > 1 ? std::to_string(a.horizon) + "-step-ahead, " : "";
    fmt::print("{}\npredicted samples {}..{} ({}{} protocol)\n{}wrote {} and {}\n", model.Summary(),
               first + 1, y.size(), ahead, a.protocol,
               window_note.empty() ? "" : window_note + "\n", a.output, SidecarPath(a.output));
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
      "  gyrodrift predict model.json test.csv --protocol causal --window 512 -o pred.csv\n"
      "writes pred.csv with columns sample (1-based row of test.csv), time_s (if test.csv has\n"
      "it) and prediction, one row per predicted sample: rows before the model has its p lags\n"
      "of history (for ms-elm/emd-elm under the causal protocol, 16 samples to decompose), and\n"
      "H-1 more with --horizon H, are left out. causal (default): the sub-series at t come from\n"
      "decomposing only the trailing window y[t-W..t-1], what a running system can do. paper:\n"
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
  BindSetting(cmd->add_option("--protocol", args->protocol, "causal|paper")->capture_default_str(),
              {"protocol"});
  BindSetting(
      cmd->add_option("--window,-W", args->window, "causal protocol: trailing window W, samples")
          ->capture_default_str(),
      {"window"});
  BindSetting(
      cmd->add_option("--horizon,-H", args->horizon,
                      "steps ahead: predict y[t] from the samples up to t-H (recursive for H > 1)")
          ->capture_default_str(),
      {"horizon"});
  BindSetting(cmd->add_option("--threads,-j", args->threads, "worker threads (0 = all cores)")
                  ->capture_default_str(),
              {"threads"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
