// gyrodrift fit: fit a drift model (MS-ELM or a baseline) on a CSV log and save it as a model file.
#include <fmt/core.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/thermal_coefficients.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/fit_task.h"
#include "gyrodrift/tasks/task_log.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

// The chosen regressors (named by the temperature columns) with their coefficients in physical
// units around the reference temperature (drift::PhysicalCoefficients), the calibration report
// and its warnings.
void PrintThermalModel(const std::string& name, const drift::ThermalRegression& t,
                       const std::vector<std::string>& channels, std::optional<double> reference_c,
                       const std::string& unit) {
  fmt::print("  {:<8} {}\n", name, t.Summary());
  const drift::ThermalCoefficients c = drift::PhysicalCoefficients(t, reference_c, channels);
  std::string around;
  if (reference_c) {
    around = fmt::format("{:.6g} degC (--reference-temperature)", *reference_c);
  } else if (c.reference_c.size() == 1) {
    around = fmt::format("{:.6g} degC (the calibration's mean)", c.reference_c[0]);
  } else {
    for (size_t i = 0; i < c.reference_c.size(); ++i) {
      around += fmt::format("{}{} {:.6g}", i ? ", " : "",
                            channels.size() == c.reference_c.size() ? channels[i]
                                                                     : fmt::format("T{}", i + 1),
                            c.reference_c[i]);
    }
    around += " degC (the calibration's means)";
  }
  fmt::print("           coefficients per K^k of (temperature or state level - reference), "
             "around {}:\n", around);
  for (const drift::PhysicalCoefficient& term : c.terms) {
    std::string note;
    // A state's first power: the level's calibration range, where the powers are polynomials.
    if (term.state >= 0 && term.unit == "/K") {
      const auto& range = c.state_range_c[static_cast<size_t>(term.state)];
      note = fmt::format("  (level {:.4g}..{:.4g} degC in calibration)", range.first,
                         range.second);
    }
    fmt::print("           {:<40} {:>12.6g} +- {:<8.2g} {}{}{}\n", term.term, term.value, term.sd,
               unit, term.unit, note);
  }
  fmt::print("           calibration: {}\n", t.report.Summary());
  if (t.autopilot.fitted()) fmt::print("           autopilot form: {}\n", t.autopilot.Summary());
  for (const std::string& w : t.report.warnings) {
    fmt::print("warning: calibration run ({}): {}\n", name, w);
  }
  for (const std::string& a : t.report.advice) {
    fmt::print("advice: calibration run ({}): {}\n", name, a);
  }
}

// What fit learnt about one axis: the model, its decomposition and grouping reports, the lag
// choice and each sub-model.
void PrintModel(const io::LoadedModel& axis, const drift::DriftOptions& o) {
  const drift::DriftModel& model = axis.model;
  fmt::print("{}\n", model.Summary());
  if (!model.decomposition_summary.empty())
    fmt::print("decomposition: {}\n", model.decomposition_summary);
  if (!model.selection_summary.empty()) fmt::print("selection: {}\n", model.selection_summary);
  if (o.auto_lags) {
    std::string rmse;
    for (size_t i = 0; i < model.lag_validation_rmse.size(); ++i) {
      rmse += fmt::format("{}p={}: {:.4g}", i ? ", " : "", o.lag_candidates[i],
                          model.lag_validation_rmse[i]);
    }
    fmt::print("lags: {} chosen by validation RMSE ({})\n", model.lags, rmse);
  }
  const std::vector<std::string> channels = SplitColumns(axis.info.temperature_column);
  for (const auto& sub : model.sub_models) {
    if (sub.thermal) {
      PrintThermalModel(sub.name, *sub.thermal, channels, o.reference_c, axis.info.rate_unit);
      continue;
    }
    if (sub.mean) {
      fmt::print(
          "  {:<8} its training mean {:.6g} (white; its learner did not beat the mean by "
          "10 % on held-out data)\n",
          sub.name, *sub.mean);
      continue;
    }
    if (sub.baseline) continue;  // the summary line above says it all
    fmt::print(
        "  {:<8} {}\n", sub.name,
        sub.learner ? sub.learner->Summary() : "zero (noise carries no thermal information)");
  }
}

struct FitArgs : DriftArgs {
  std::string method = "auto";
  std::string units = io::ModelFileInfo{}.rate_unit;  // of the target(s), kept in the model file
  std::string output;
};

// The calibration logs as one run of several records: the targets' columns, then the
// temperatures', of every log one after the other (tasks::AssembleFitRun). Notes and the
// warnings to print before the work go to *notes and *warnings.
tasks::FitRun ReadRun(const FitArgs& a, std::string* notes, std::string* warnings) {
  const io::LogOptions log = a.log.Options();
  std::vector<tasks::TaskLog> logs;
  for (const std::string& input : a.inputs) {
    tasks::TaskLog l = tasks::ReadTaskLog(input, log, GivenRateHz(a));
    if (!l.gap_note.empty()) *notes += l.gap_note + "\n";
    if (!l.time_note.empty()) *notes += (a.inputs.size() > 1 ? input + ": " : "") + l.time_note + "\n";
    // Each log's columns are checked where they are read, before its warnings.
    (void)tasks::ReadColumns(l.table, a.target, "--target");
    const std::vector<std::string> temperatures =
        a.temperature.empty() ? std::vector<std::string>{}
                              : tasks::ReadColumns(l.table, a.temperature, "--temperature").names;
    for (const std::string& w :
         tasks::LogWarnings(l, l.rate_how, temperatures, tasks::Audience::kFlags)) {
      *warnings += "warning: " + w + "\n";
    }
    logs.push_back(std::move(l));
  }
  return tasks::AssembleFitRun(logs, a.target, a.temperature, log);
}

void Run(const FitArgs& a) {
  RequireOutputsAreNotInputs(a.inputs, {a.output});
  const drift::FitSettings settings = Settings(a, a.method);
  settings.Validate();  // option errors before any file is read
  std::string notes, warnings;
  const tasks::FitRun run = ReadRun(a, &notes, &warnings);
  tasks::CheckFitRun(run, drift::MakeDriftOptions(settings), a.log.Options());
  // What the user must know before waiting for the fit: an assumed rate, a temperature that
  // does not look like degC.
  if (!a.quiet && !warnings.empty()) {
    fmt::print("{}", warnings);
    std::fflush(stdout);
  }
  const auto axes = static_cast<int>(run.targets.size());
  tasks::FitResult fit;
  {
    ProgressBar progress(std::vector<double>(static_cast<size_t>(axes), 1.0),
                         IsTerminal() && !a.quiet);
    std::string label;
    const std::string method(drift::ToString(drift::MakeDriftOptions(settings).method));
    fit = tasks::RunFit(run, settings, a.units, a.log.Options(),
                        [&](int axis, double fraction, std::string_view step) {
                          if (step.empty()) {  // the axis starts
                            label = axes > 1 ? run.targets[static_cast<size_t>(axis)] + ": " + method
                                             : method;
                            progress.BeginStage(axis, label);
                            return;
                          }
                          progress.Update(fraction, label + ": " + std::string(step));
                        });
  }
  io::WriteFileAtomically(a.output, fit.ModelFile());
  if (a.quiet) return;
  for (const io::LoadedModel& axis : fit.axes) {
    if (axes > 1) fmt::print("axis {}:\n", axis.info.target_column);
    PrintModel(axis, fit.options);
  }
  fmt::print("sample rate: {} Hz ({})\n{}wrote {}\n", fit.options.features.rate_hz,
             tasks::RateSourceText(run.rate_how, /*flags=*/true), notes, a.output);
}

const RegisterCommand kRegister("fit", 50, [](CLI::App& app) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fit", "Fit a drift model (MS-ELM or a baseline) on a log and save it as a model file.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift simulate --duration 8h --seed 7 -o train.csv\n"
      "  gyrodrift fit train.csv --target rate_dph --temperature temperature_c \\\n"
      "      --mode compensate --method ms-elm --seed 1 -o model.json\n"
      "  gyrodrift compensate model.json test.csv -o compensated.csv\n"
      "Modes: predict = one-step-ahead prediction of the output from its own past (the paper's\n"
      "task; --temperature adds the thermal history); compensate = drift estimated from the\n"
      "temperature alone, what a navigation computer runs: the thermal method identifies which\n"
      "thermal states (lags of the temperature with their time constants, powers and rates) the\n"
      "drift follows, by cross-validation over the calibration run. ms-elm decomposes the record\n"
      "(BEEMDAN), groups the IMFs into noise/mixed/drift and fits one ELM per group; emd-elm\n"
      "fits one ELM per IMF; elm, poly, svr, bp are single models on the raw signal.\n"
      "model.json holds every option, the training column names and the fitted parameters\n"
      "(exact doubles, checksummed). Several targets (--target gyro_x,gyro_y,gyro_z) are fitted\n"
      "one by one with the same options into one model file, one model per axis.\n"
      "Several calibration logs (fit day1.csv day2.csv ...), or one split at its gaps\n"
      "(--gaps split), are fitted by the thermal method as records of one calibration: its\n"
      "lag states restart at the start of each. A duty-cycled log (5 s of every 300 s) is fitted\n"
      "with --gaps carry: the lag states run across the gaps on the interpolated temperature,\n"
      "the fit uses the logged rows only (compensate mode, thermal or a single learner).\n"
      "See docs/cli.md and docs/drift.md.");
  AddDriftOptions(cmd, args.get(), /*split_records=*/true);
  BindSetting(cmd->add_option("--method,-m", args->method,
                              "auto|ms-elm|thermal|elm|emd-elm|poly|svr|bp, the predict-mode "
                              "baselines persistence|trailing-mean|exp-smoothing|kalman-level|"
                              "kalman-trend, or the references none|constant (auto: ms-elm in "
                              "predict mode, thermal in compensate mode)")
                  ->capture_default_str(),
              {"method"});
  cmd->add_option("--units", args->units,
                  "unit of the target column(s), recorded in the model file and used in reports: "
                  "dph (deg/h) | dps (deg/s) | rads (rad/s)")
      ->check(CLI::IsMember({"dph", "dps", "rads"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output,
                  "model file to write (JSON; one model per --target column)")
      ->required();
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
