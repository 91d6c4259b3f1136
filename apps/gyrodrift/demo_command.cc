// gyrodrift demo: the whole study in one command. Without files: simulate a navigation-grade FOG
// through two thermal-chamber programmes, decompose and group its output, fit MS-ELM and every
// baseline in predict mode (paper and causal protocols) and compensate mode (trained on run A,
// tested on run B), compare the Allan deviation before and after compensation, and write data,
// models, tables and one self-contained HTML report to a folder. With --input: the same study on
// a user's log (scored against the measured output; compensate mode by chronological split).
// The study is gyrodrift::study (include/gyrodrift/study/), run by study::RunDemo (demo.h); this
// file turns the flags into its settings, drives the progress bar and prints.
#include <fmt/core.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/study/demo.h"
#include "gyrodrift/study/study.h"
#include "gyrodrift/study/study_files.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

struct DemoArgs {
  study::DemoSettings settings;  // the defaults are the library's
  std::string duration;          // as typed; empty: settings.duration_s, the library's default
  double rate_hz = 1.0;
  CLI::Option* rate_option = nullptr;  // "--rate-hz given"
  LogArgs log;                         // --gaps, --delimiter
  bool quiet = false;
};

// The settings of the flags. A range refused by the library names the flag (BindSetting); the
// duration as typed ("90min"), not the seconds it became.
study::DemoSettings Settings(const DemoArgs& a) {
  study::DemoSettings s = a.settings;
  s.log = a.log.Options();
  if (a.rate_option->count() > 0) s.rate_hz = a.rate_hz;
  if (!a.duration.empty()) s.duration_s = ParseDuration(a.duration);
  try {
    (void)s.Options();
  } catch (const OptionError& e) {
    if (e.option() == "duration_s") ThrowOption("--duration", a.duration, e.rule());
    throw;
  }
  return s;
}

void Run(const DemoArgs& a) {
  const study::DemoSettings settings = Settings(a);  // every mistake before the work
  ProgressBar bar(study::DemoStageWeights(settings.input.empty()), !a.quiet);
  std::atomic<int> bar_stage{-1};
  study::StudyContext context;
  context.threads = settings.threads;
  context.progress = [&](int stage, double fraction, const std::string& what) {
    if (bar_stage.exchange(stage) != stage) {
      bar.BeginStage(stage, what);
    } else {
      bar.Update(fraction, what);
    }
  };
  context.stage_done = [&](int, const std::string& summary) {
    if (!a.quiet) bar.Print(summary);
  };
  const study::DemoRun run = study::RunDemo(settings, context);
  bar.Finish();
  if (!a.quiet) {
    size_t report_bytes = 0;
    for (const auto& f : run.files) {
      if (f.name == study::kStudyReportFile) report_bytes = f.contents.size();
    }
    fmt::print("6. wrote {} files to {} (report: {}, {:.1f} MB) in {:.1f} s of wall time\n",
               run.files.size(), settings.output,
               (std::filesystem::path(settings.output) / study::kStudyReportFile).string(),
               static_cast<double>(report_bytes) / 1e6, run.seconds);
  }
}

// The study's size options (the "Advanced" group of --help).
void AddAdvancedOptions(CLI::App* cmd, DemoArgs& a) {
  BindSetting(
      cmd->add_option("--duration", a.duration,
                      "advanced: length of each simulated run, at least 2h (2h, 150min, 8h)")
          ->default_str(FormatValue(study::DemoSettings{}.duration_s / 3600.0) + "h")
          ->group("Advanced"),
      {"duration_s"});
  BindSetting(cmd->add_option("--ensemble", a.settings.ensemble, "advanced: BEEMDAN ensemble size")
                  ->capture_default_str()
                  ->group("Advanced"),
              {"ensemble_size"});
  BindSetting(
      cmd->add_option(
             "--realisations", a.settings.realisations,
             "advanced: white-noise realisations of the selection's Monte-Carlo level (>= 20)")
          ->capture_default_str()
          ->group("Advanced"),
      {"realisations"});
  AddCausalWindowOptions(cmd, &a.settings.causal, "Advanced");
  BindSetting(cmd->add_option("--methods", a.settings.methods,
                              "advanced: all, or a list such as ms-elm,elm,poly")
                  ->capture_default_str()
                  ->group("Advanced"),
              {"methods"});
}

const RegisterCommand kRegister("demo", 5, [](CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "The whole study in one command: simulate, decompose, model, compensate, report.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift demo                       # simulated FOG, about 30 s on 2 cores -> "
      "./gyrodrift-demo/\n"
      "  gyrodrift demo -o /tmp/study\n"
      "  gyrodrift demo --input log.csv --target gyro_x --temperature temp --rate-hz 1\n"
      "Writes run_a.csv, run_b.csv (simulation), imfs.csv, selection.csv, predict_table.csv,\n"
      "compensate_table.csv, predict_estimates.csv, compensate_estimates.csv, allan.csv,\n"
      "noise_terms.csv, models/<method>_compensate.json, demo.json and report.html (open it in a\n"
      "browser; it works offline). The study's size options (--duration, --ensemble, --window,\n"
      "--windows, --causal-ensemble, --realisations, --methods) trade fidelity for time;\n"
      "docs/demo.md lists the defaults' cost.");
  cmd->add_option("-o,--output", args->settings.output, "output folder (created if needed)")
      ->capture_default_str();
  cmd->add_option("--input", args->settings.input,
                  "a uniformly sampled CSV log of your own instead of the simulation")
      ->check(kInputFile);
  cmd->add_option("--target", args->settings.target,
                  "with --input: the gyro output column (name or 1-based index)");
  cmd->add_option("--temperature", args->settings.temperature,
                  "with --input: the temperature column");
  args->rate_option = BindSetting(
      cmd->add_option("--rate-hz", args->rate_hz,
                      "with --input: sample rate, Hz (default: from a time_s column, else 1)"),
      {"rate_hz"});
  BindSetting(cmd->add_option("--units", args->settings.units,
                              "unit of the --input target for the Allan noise terms: dph|dps|rads")
                  ->capture_default_str(),
              {"units"});
  cmd->add_option(
         "--seed", args->settings.seed,
         "seed of the simulation (run A; run B derives its own), decomposition and learners")
      ->capture_default_str()
      ->check(kSeed);
  BindSetting(
      cmd->add_option("--threads,-j", args->settings.threads, "worker threads (0 = all cores)")
          ->capture_default_str(),
      {"threads"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "no progress bar and no tables on the terminal");
  AddAdvancedOptions(cmd, *args);
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
