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
#include "gyrodrift/tasks/evaluate_task.h"
#include "gyrodrift/tasks/task_log.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct EvaluateArgs : DriftArgs {
  std::string truth;
  tasks::EvaluateSettings evaluation;  // but for its fit settings, DriftArgs'
  std::string output;
};

// The settings of the flags (the model settings as fit's).
tasks::EvaluateSettings EvaluationSettings(const EvaluateArgs& a) {
  tasks::EvaluateSettings s = a.evaluation;
  s.fit = Settings(a, "ms-elm");
  return s;
}

// The record as the log gives it: the target, the temperatures, the truth; *input what the
// sidecar says of it.
struct Record {
  Eigen::VectorXd y, truth;
  Eigen::MatrixXd temperature;
  std::vector<std::string> temperature_names;
};
Record ReadRecord(const EvaluateArgs& a, const io::CsvTable& table, tasks::EvaluateInput* in) {
  Record r;
  in->target_column = ColumnName(table, a.target);
  r.y = table.Column(a.target);
  if (!a.temperature.empty()) {
    SelectedColumns t = ReadColumns(table, a.temperature, "--temperature");
    // The target as a model input would score the target against itself (fit refuses it too).
    if (std::find(t.names.begin(), t.names.end(), in->target_column) != t.names.end()) {
      throw UsageError("--temperature = " + a.temperature + ": must differ from --target");
    }
    in->temperature_column = t.joined;
    r.temperature = std::move(t.values);
    r.temperature_names = std::move(t.names);
  }
  in->samples = r.y.size();
  return r;
}

void Run(const EvaluateArgs& a) {
  RequireOutputsAreNotInputs(a.inputs, {a.output, SidecarPath(a.output)});
  tasks::EvaluateSettings settings = EvaluationSettings(a);
  settings.Validate("--methods");  // option errors before any file is read
  if (a.target.find(',') != std::string::npos) {
    throw UsageError("--target = " + a.target +
                     ": evaluate scores one axis at a time (fit takes several targets)");
  }
  a.log.RequireOneRecord("evaluate", "it splits one record chronologically and scores every "
                         "method on it; fit --gaps " + a.log.gaps + " and compensate take records");
  const tasks::TaskLog log = tasks::ReadTaskLog(a.inputs.front(), a.log.Options(), GivenRateHz(a));
  const io::CsvTable& table = log.table;
  tasks::EvaluateInput in{.input = a.inputs.front(), .rate_hz_from = log.rate_how};
  settings.fit.rate_hz = log.rate_hz;
  Record record = ReadRecord(a, table, &in);
  // Before the work: an assumed sample rate, a temperature that does not look like degC.
  if (!a.quiet) {
    for (const std::string& w :
         tasks::LogWarnings(log, log.rate_how, record.temperature_names, tasks::Audience::kFlags)) {
      fmt::print("warning: {}\n", w);
    }
    std::fflush(stdout);
  }
  if (!a.truth.empty()) {
    in.truth_column = ColumnName(table, a.truth);
    if (in.truth_column == in.target_column)
      throw UsageError("--truth = " + a.truth + ": must differ from --target");
    const std::vector<std::string>& inputs = record.temperature_names;
    if (std::find(inputs.begin(), inputs.end(), in.truth_column) != inputs.end()) {
      throw UsageError("--truth = " + a.truth +
                       ": must differ from --temperature (the models "
                       "would read the truth they are scored against)");
    }
    record.truth = table.Column(a.truth);
  }
  tasks::EvaluateRun run;
  {
    ProgressBar progress({1.0}, IsTerminal() && !a.quiet);  // Finish() on every exit path
    progress.BeginStage(0, "evaluate");
    run = tasks::RunEvaluate(record.y, record.temperature, record.truth, settings,
                             [&progress](double fraction, std::string_view label) {
                               progress.Update(fraction, std::string(label));
                             },
                             "--methods");
  }
  nlohmann::json sidecar = SidecarHeader("evaluate");
  sidecar.update(tasks::EvaluateRecord(run, in));
  std::string notes;
  for (const std::string* note : {&log.gap_note, &log.time_note}) {
    if (!note->empty()) notes += *note + (note->back() == '\n' ? "" : "\n");
  }
  if (run.result.mode == drift::Mode::kPredict) notes += MadeUpRowsPredictionNote(log.logged);
  notes += tasks::EvaluateNotes(run);
  io::WriteFilesAtomically({{a.output, tasks::EvaluateTableCsv(run.result)},
                            {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (a.quiet) return;
  const drift::EvaluationResult& result = run.result;
  const std::string ahead = run.options.horizon > 1
                                ? fmt::format(" ({}-step-ahead predictions)", run.options.horizon)
                                : "";
  fmt::print("{} mode{}, trained on samples 1..{}, scored on {}..{} against {}\n{}{}wrote {} and {}\n",
             drift::ToString(result.mode), ahead, result.split_index, result.split_index + 1,
             record.y.size(), result.against_truth ? in.truth_column : in.target_column,
             result.Table(), notes, a.output, SidecarPath(a.output));
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
      "mean) are always scored first. Single models and baselines never decompose, and in\n"
      "compensate mode only the training block is decomposed: their two rows are the same run.\n"
      "Writes table.csv (method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,\n"
      "train_s,predict_s) and table.csv.json.");
  AddDriftOptions(cmd, args.get(), /*split_records=*/false);
  cmd->add_option("--truth", args->truth, "column to score against (e.g. drift_dph)");
  BindSetting(
      cmd->add_option("--protocol", args->evaluation.protocol, "paper|causal|both")->capture_default_str(),
      {"protocol", "protocols"});
  BindSetting(
      cmd->add_option("--split", args->evaluation.split, "training share of the record, in [0.1, 0.95]")
          ->capture_default_str(),
      {"split"});
  BindSetting(cmd->add_option("--methods", args->evaluation.methods,
                              "all, or a comma-separated list of ms-elm,elm,emd-elm,poly,svr,bp,"
                              "thermal (compensate), persistence,trailing-mean,exp-smoothing,"
                              "kalman-level,kalman-trend (predict); none and constant are always "
                              "scored")
                  ->capture_default_str(),
              {"methods"});
  BindSetting(cmd->add_option("--repeats,-r", args->evaluation.repeats,
                              "repeats: the first with --seed, repeat r > 0 with a seed derived "
                              "from --seed and r; mean and std over them")
                  ->capture_default_str(),
              {"repeats"});
  AddCausalWindowOptions(cmd, &args->evaluation.causal);
  BindSetting(cmd->add_option("--horizon,-H", args->evaluation.horizon,
                              "predict mode: score H-step-ahead predictions (recursive for H > 1)")
                  ->capture_default_str(),
              {"horizon"});
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
