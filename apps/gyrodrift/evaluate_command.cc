// gyrodrift evaluate: MS-ELM against the baselines on one log, chronological split, both protocols.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct EvaluateArgs : DriftArgs {
  std::string truth;
  std::string protocol = "both";
  double split = drift::EvaluationOptions{}.split;
  std::string methods = "all";
  int repeats = drift::EvaluationOptions{}.repeats;
  int window = drift::CausalOptions{}.window;
  int horizon = drift::EvaluationOptions{}.horizon;
  std::string output;
};

std::vector<drift::Protocol> ParseProtocols(const std::string& text) {
  if (text == "both") return {drift::Protocol::kPaper, drift::Protocol::kCausal};
  if (text != "paper" && text != "causal")
    ThrowOption("--protocol", "'" + text + "'", "paper, causal or both");
  return {drift::ProtocolFromString(text)};
}

std::string TableCsv(const drift::EvaluationResult& result) {
  std::string csv =
      "method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,train_s,predict_s\n";
  for (const auto& r : result.rows) {
    csv += std::string(drift::ToString(r.method)) + "," + std::string(drift::ToString(r.protocol));
    for (double v : {r.rmse, r.rmse_std, r.mae, r.max_abs, r.rmse_measured, r.slow_removed,
                     r.train_s, r.predict_s}) {
      csv += "," + io::FormatDouble(v);
    }
    csv += "\n";
  }
  return csv;
}

void Run(const EvaluateArgs& a) {
  RequireOutputsAreNotInputs(a.inputs, {a.output, SidecarPath(a.output)});
  const drift::FitSettings settings = Settings(a, "ms-elm");
  drift::DriftOptions base = drift::MakeDriftOptions(settings);
  Execution execution = drift::MakeExecution(settings);
  drift::EvaluationOptions e;
  e.split = a.split;
  e.repeats = a.repeats;
  e.methods = ParseMethods(a.methods, base.mode);
  e.protocols = ParseProtocols(a.protocol);
  e.causal.window = a.window;
  e.horizon = a.horizon;
  e.Validate();  // option errors before any file is read
  if (a.target.find(',') != std::string::npos) {
    throw UsageError("--target = " + a.target +
                     ": evaluate scores one axis at a time (fit takes several targets)");
  }

  a.log.RequireOneRecord("evaluate", "it splits one record chronologically and scores every "
                         "method on it; fit --gaps " + a.log.gaps + " and compensate take records");
  std::string gap_note;
  const io::CsvTable table = ReadLog(a.inputs.front(), a.log, &gap_note);
  std::string rate_how;
  base.features.rate_hz = ResolveRateHz(a, table, &rate_how);
  const std::string target = ColumnName(table, a.target);
  const Eigen::VectorXd y = table.Column(a.target);
  Eigen::MatrixXd temperature;
  Eigen::VectorXd truth;
  std::string temperature_column, truth_column;
  std::vector<std::string> temperature_names;
  if (!a.temperature.empty()) {
    SelectedColumns t = ReadColumns(table, a.temperature, "--temperature");
    temperature_column = t.joined;
    temperature = std::move(t.values);
    temperature_names = std::move(t.names);
  }
  // Before the work: an assumed sample rate, a temperature that does not look like degC.
  if (!a.quiet) {
    fmt::print("{}", InputWarnings(a.inputs.front(), rate_how, table, temperature_names));
    std::fflush(stdout);
  }
  if (!a.truth.empty()) {
    truth_column = ColumnName(table, a.truth);
    if (truth_column == target)
      throw UsageError("--truth = " + a.truth + ": must differ from --target");
    truth = table.Column(a.truth);
  }

  drift::EvaluationResult result;
  {
    ProgressBar progress({1.0}, IsTerminal() && !a.quiet);  // Finish() on every exit path
    progress.BeginStage(0, "evaluate");
    execution.progress = [&progress](double fraction, std::string_view label) {
      progress.Update(fraction, std::string(label));
    };
    result = drift::Evaluate(y, temperature, truth, base, e, execution);
  }

  nlohmann::json methods = nlohmann::json::array(), protocols = nlohmann::json::array();
  for (auto m : e.methods) methods.push_back(drift::ToString(m));
  for (auto p : e.protocols) protocols.push_back(drift::ToString(p));
  nlohmann::json sidecar = SidecarHeader("evaluate");
  sidecar["options"] = {{"input", a.inputs.front()},
                        {"target_column", target},
                        {"temperature_column", temperature_column},
                        {"truth_column", truth_column},
                        {"split", e.split},
                        {"repeats", e.repeats},
                        {"methods", methods},
                        {"protocols", protocols},
                        {"window", e.causal.window},
                        {"horizon", e.horizon},
                        {"rate_hz_from", rate_how},
                        {"threads", execution.threads},
                        {"drift", io::DriftOptionsToJson(base)}};
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : result.rows) {
    rows.push_back({{"method", drift::ToString(r.method)},
                    {"protocol", drift::ToString(r.protocol)},
                    {"rmse", r.rmse},
                    {"rmse_std", r.rmse_std},
                    {"mae", r.mae},
                    {"max_abs", r.max_abs},
                    {"rmse_measured", r.rmse_measured},
                    // null: a test block shorter than one 10-min block
                    {"slow_removed", std::isfinite(r.slow_removed) ? nlohmann::json(r.slow_removed)
                                                                   : nlohmann::json(nullptr)},
                    {"train_s", r.train_s},
                    {"predict_s", r.predict_s},
                    {"model_summary", r.model_summary},
                    {"notes", r.notes}});
  }
  // Test temperatures beyond the training block's make every thermal model extrapolate.
  std::string notes = gap_note + NonUniformTimeNote(table);
  if (!notes.empty() && notes.back() != '\n') notes += "\n";
  for (const auto& r : result.rows) {
    for (const std::string& note : r.notes) {
      notes += std::string(drift::ToString(r.method)) + ", " + note + "\n";
    }
  }
  const double outside = result.test_outside_training_temperature_share;
  if (outside > 0.0) {
    notes += fmt::format(
        "note: {:.1f} % of the test samples lie outside the training temperature range "
        "[{:.4g}, {:.4g}] degC: thermal models extrapolate there\n",
        100.0 * outside, result.training_temperature_min_c, result.training_temperature_max_c);
  }
  sidecar["result"] = {{"mode", drift::ToString(result.mode)},
                       {"test_outside_training_temperature_share", outside},
                       {"samples", y.size()},
                       {"first_test_sample", result.split_index + 1},
                       {"test_samples", y.size() - result.split_index},
                       {"scored_against", result.against_truth ? truth_column : target},
                       {"slow_variation_block_s", drift::kSlowVariationBlockS},
                       {"rows", rows}};
  io::WriteFilesAtomically(
      {{a.output, TableCsv(result)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) {
    const std::string ahead =
        e.horizon > 1 ? fmt::format(" ({}-step-ahead predictions)", e.horizon) : "";
    fmt::print(
        "{} mode{}, trained on samples 1..{}, scored on {}..{} against {}\n{}{}wrote {} and {}\n",
        drift::ToString(result.mode), ahead, result.split_index, result.split_index + 1, y.size(),
        result.against_truth ? truth_column : target, result.Table(), notes, a.output,
        SidecarPath(a.output));
  }
}

const RegisterCommand kRegister("evaluate", 80, [](CLI::App& app) {
  auto args = std::make_shared<EvaluateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Compare MS-ELM with the baselines: chronological split, paper and causal protocols.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift simulate --duration 8h --seed 7 -o fog.csv\n"
      "  gyrodrift evaluate fog.csv --target rate_dph --temperature temperature_c \\\n"
      "      --truth drift_dph --mode compensate --methods ms-elm,elm,poly --repeats 3 -o "
      "table.csv\n"
      "Fits each method on the first --split of the record and scores it on the rest: RMSE, its\n"
      "std over --repeats seeds, MAE, max |error|, the RMSE against the measured target, the\n"
      "share of the slow variation (RMS of 10-min block means) removed, and wall-clock times.\n"
      "Scores are against --truth when given (the simulator's drift), else against the target\n"
      "itself. Predict mode: one-step-ahead error (--horizon H: H steps ahead, recursive);\n"
      "compensate mode: error of the drift estimate. paper = decompose the whole record before\n"
      "splitting (test sub-series see the future, as in the literature); causal = only past\n"
      "samples reach a prediction. The references none (zero estimate) and constant (training\n"
      "mean) are always scored first. Single models and baselines never decompose, so their\n"
      "two rows are the same run. Writes table.csv (method,protocol,rmse,rmse_std,mae,max_abs,\n"
      "rmse_measured,slow_removed,train_s,predict_s) and table.csv.json.");
  AddDriftOptions(cmd, args.get(), /*split_records=*/false);
  cmd->add_option("--truth", args->truth, "column to score against (e.g. drift_dph)");
  BindSetting(
      cmd->add_option("--protocol", args->protocol, "paper|causal|both")->capture_default_str(),
      {"protocol", "protocols"});
  BindSetting(
      cmd->add_option("--split", args->split, "training share of the record, in [0.1, 0.95]")
          ->capture_default_str(),
      {"split"});
  BindSetting(cmd->add_option("--methods", args->methods,
                              "all, or a comma-separated list of ms-elm,elm,emd-elm,poly,svr,bp,"
                              "thermal (compensate), persistence,trailing-mean,exp-smoothing,"
                              "kalman-level,kalman-trend (predict); none and constant are always "
                              "scored")
                  ->capture_default_str(),
              {"methods"});
  BindSetting(
      cmd->add_option("--repeats,-r", args->repeats, "seeds seed..seed+R-1; mean and std over them")
          ->capture_default_str(),
      {"repeats"});
  BindSetting(
      cmd->add_option("--window,-W", args->window, "causal protocol: trailing window W, samples")
          ->capture_default_str(),
      {"causal.window"});
  BindSetting(cmd->add_option("--horizon,-H", args->horizon,
                              "predict mode: score H-step-ahead predictions (recursive for H > 1)")
                  ->capture_default_str(),
              {"horizon"});
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
