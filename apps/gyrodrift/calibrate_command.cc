// gyrodrift calibrate: the thermal calibration of a fleet of gyros from a TOML manifest
// (fleet/calibration.h): per unit and axis, fit, compensate the verification logs, Allan before
// and after, pass/fail; then fleet.csv and fleet.html.
#include <fmt/core.h>

#include <memory>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/fleet/manifest.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct CalibrateArgs {
  std::string manifest;
  std::string output;
  bool force = false;
  int threads = 0;
  bool quiet = false;
};

void Run(const CalibrateArgs& a) {
  ValidateThreads(a.threads);  // named as --threads, the flag bound to it
  const fleet::Manifest manifest = fleet::ReadManifest(a.manifest);
  fleet::CheckLogColumns(manifest);  // every column of every log, before any unit is fitted

  fleet::FleetOptions o;
  o.output_dir = a.output;
  o.force = a.force;
  fleet::FleetContext context;
  context.threads = a.threads;
  ProgressBar progress({1.0}, IsTerminal() && !a.quiet);
  progress.BeginStage(0, "calibrate");
  context.progress = [&](int done, int total, const std::string& serial, const std::string& what) {
    progress.Update(static_cast<double>(done) / total, fmt::format("{}/{} units", done, total));
    if (!a.quiet) progress.Print(fmt::format("{:<16} {}\n", serial, what));
  };
  const fleet::FleetResult result = fleet::RunFleet(manifest, o, context);
  progress.Finish();
  if (!a.quiet) {
    for (const fleet::FleetRow& row : result.rows) {
      if (row.cells[3] == "error") fmt::print("error: unit {}: {}\n", row.cells[0], row.cells[4]);
      if (row.cells[3] == "fail") {
        fmt::print("fail: unit {} axis {} ({}): {}\n", row.cells[0], row.cells[1], row.cells[2],
                   row.cells[4]);
      }
    }
    fmt::print("{}\nwrote {}/fleet.csv and {}/fleet.html\n", result.Summary(), a.output, a.output);
  }
  if (!result.all_pass()) {
    throw FleetFailure(fmt::format(
        "{} of {} units did not pass ({} failed their limits, {} could not be calibrated): see "
        "{}/fleet.csv",
        result.failed_limits + result.errors, result.units, result.failed_limits, result.errors,
        a.output));
  }
}

const RegisterCommand kRegister("calibrate", 75, [](CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Calibrate a fleet of gyros from a TOML manifest (fit, verify, Allan, limits).");
  cmd->footer(
      "Example:\n"
      "  gyrodrift calibrate fleet.toml -o calibration\n"
      "For every unit of the manifest and every axis: fit the compensate-mode model on the\n"
      "calibration log, compensate each verification log, measure the residual drift and the\n"
      "Allan deviation (IEEE 952 terms) before and after, and check the limits. Writes\n"
      "calibration/<serial>/ (model.json, verification_K_compensated.csv, allan.csv,\n"
      "report.html, summary.json) and calibration/fleet.csv, calibration/fleet.html. Units run\n"
      "in parallel; a rerun skips units whose logs and settings did not change (--force redoes\n"
      "them); a unit that fails is reported and the others go on. Exit code 5 when a unit failed\n"
      "its limits or could not be calibrated. The manifest format: docs/calibration.md.");
  cmd->add_option("manifest", args->manifest, "calibration manifest (TOML)")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "output folder (created if missing)")->required();
  cmd->add_flag("--force", args->force, "redo units already calibrated with the same settings");
  BindSetting(
      cmd->add_option("--threads,-j", args->threads, "units calibrated at once (0: every core)")
          ->capture_default_str(),
      {"threads"});
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
