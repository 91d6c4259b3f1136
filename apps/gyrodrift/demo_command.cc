// gyrodrift demo: the whole study in one command. Without files: simulate a navigation-grade FOG
// through two thermal-chamber programmes, decompose and group its output, fit MS-ELM and every
// baseline in predict mode (paper and causal protocols) and compensate mode (trained on run A,
// tested on run B), compare the Allan deviation before and after compensation, and write data,
// models, tables and one self-contained HTML report to a folder. With --input: the same study on
// a user's log (scored against the measured output; compensate mode by chronological split).
// The study is gyrodrift::study (include/gyrodrift/study/); this file turns the flags into its
// options, reads the log, drives the progress bar, prints and writes what the study renders.
#include <fmt/core.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/study/study.h"
#include "gyrodrift/study/study_files.h"
#include "gyrodrift/tasks/evaluate_task.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct DemoArgs {
  std::string output = "gyrodrift-demo";
  std::string input, target, temperature;
  double rate_hz = 1.0;
  CLI::Option* rate_option = nullptr;
  std::string units = "dph";
  // Advanced: the size of the study. Defaults keep the full demo under 3 minutes on 2 cores.
  std::string duration = "8h";
  int ensemble = study::StudyOptions{}.ensemble_size;
  int realisations = study::StudyOptions{}.realisations;
  int window = study::StudyOptions{}.causal_window;
  std::string methods = "all";
  std::uint64_t seed = study::StudyOptions{}.seed;
  int threads = 0;
  LogArgs log;  // --gaps, --delimiter
  CLI::Option* units_option = nullptr;  // "--units given"
  bool quiet = false;
};

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The flags' syntax is checked here; their ranges by StudyOptions::Validate, whose field names
// OptionErrorMessage turns back into the flags the user typed.
study::StudyOptions MakeStudyOptions(const DemoArgs& a) {
  study::StudyOptions o;
  try {
    o.units = allan::RateUnitFromString(a.units);
  } catch (const UsageError&) {
    ThrowOption("--units", a.units, "one of dph, dps, rads");
  }
  o.methods = tasks::ParseMethods(a.methods, drift::Mode::kCompensate, "--methods");
  o.duration_s = ParseDuration(a.duration);
  o.ensemble_size = a.ensemble;
  o.realisations = a.realisations;
  o.causal_window = a.window;
  o.seed = a.seed;
  try {
    o.Validate();
    ValidateThreads(a.threads);
  } catch (const OptionError& e) {
    // The duration as typed ("90min"), not the seconds it became.
    if (e.option() == "duration_s") ThrowOption("--duration", a.duration, e.rule());
    throw;
  }
  return o;
}

study::StudyLog ReadStudyLog(const DemoArgs& a) {
  const auto start = Clock::now();
  a.log.RequireOneRecord("demo", "the study decomposes and splits one record");
  std::string notes;
  const io::CsvTable table = ReadLog(a.input, a.log, &notes);
  study::StudyLog log;
  log.source = a.input;
  log.output = table.Column(a.target);
  log.temperature = table.Column(a.temperature);
  log.target_name = ColumnName(table, a.target);
  log.temperature_name = ColumnName(table, a.temperature);
  // A given rate is taken as given (the study checks its range), never replaced by time_s's.
  std::string how = "given";
  log.rate_hz = a.rate_option->count() > 0 ? a.rate_hz : ResolveSampleRate(table, 0.0, &how);
  log.rate_source = RateSourceText(how);
  log.time_note = notes + NonUniformTimeNote(table);
  if (!log.time_note.empty() && log.time_note.back() == '\n') log.time_note.pop_back();
  log.read_s = Seconds(start);
  return log;
}

// demo.json: the tool, the flags as given and the study's own record.
std::string DemoRecord(const DemoArgs& a, const study::StudyResult& s) {
  nlohmann::json sidecar = SidecarHeader("demo");
  sidecar.update(study::StudyRecord(s));
  sidecar["options"] = {{"output", a.output},
                        {"input", a.input},
                        {"target", a.target},
                        {"temperature", a.temperature},
                        {"rate_hz", s.rate_hz},
                        {"rate_source", s.rate_source},
                        {"units", a.units},
                        {"duration_s", s.simulated ? s.options.duration_s : 0.0},
                        {"ensemble", a.ensemble},
                        {"realisations", a.realisations},
                        {"window", a.window},
                        {"methods", a.methods},
                        {"seed", a.seed},
                        {"threads", a.threads}};
  return sidecar.dump(2) + "\n";
}

void Run(const DemoArgs& a) {
  RequireInputsOutsideFolder({a.input}, a.output);
  const auto wall_start = Clock::now();
  // Options first: every mistake is reported before any work (but the range of --rate-hz, which
  // the study checks with the log's other data).
  const bool user = !a.input.empty();
  // The simulated output is in deg/h: --units describes a user's log only.
  if (!user && (!a.target.empty() || !a.temperature.empty() || a.rate_option->count() > 0 ||
                a.units_option->count() > 0 || a.log.Given())) {
    throw UsageError(
        "--target, --temperature, --rate-hz, --units, --gaps and --delimiter need --input FILE.csv");
  }
  if (user && a.target.empty())
    throw UsageError("--input needs --target COL (the gyro output column)");
  if (user && a.temperature.empty()) {
    throw UsageError(
        "--input needs --temperature COL (compensate mode models drift from temperature)");
  }
  const study::StudyOptions options = MakeStudyOptions(a);
  // The report needs dygraphs and the files need their folder; find out now, not after the work.
  const html::DygraphsAssets assets = html::LoadDygraphs();
  study::RequireUsableOutputFolder(a.output);

  // Stage weights: seconds the stages took in the measured runs (docs/demo.md); the last stage,
  // writing the files, is this command's.
  ProgressBar bar(user ? std::vector<double>{0.1, 0.5, 12, 5, 0.1, 1}
                       : std::vector<double>{0.2, 5, 68, 22, 0.1, 3},
                  !a.quiet);
  std::atomic<int> bar_stage{-1};
  study::StudyContext context;
  context.threads = a.threads;
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
  study::StudyResult result;
  if (user) {
    bar_stage = 0;
    bar.BeginStage(0, "reading " + a.input);
    result = study::RunStudy(options, ReadStudyLog(a), context);
  } else {
    result = study::RunStudy(options, context);
  }

  bar.BeginStage(study::kStudyStages, "writing " + a.output);
  std::vector<study::StudyFile> files = study::RenderStudyFiles(result, assets);
  files.push_back({"demo.json", DemoRecord(a, result)});
  study::WriteStudyFiles(a.output, files);
  bar.Finish();
  if (!a.quiet) {
    size_t report_bytes = 0;
    for (const auto& f : files) {
      if (f.name == study::kStudyReportFile) report_bytes = f.contents.size();
    }
    fmt::print("6. wrote {} files to {} (report: {}, {:.1f} MB) in {:.1f} s of wall time\n",
               files.size(), a.output,
               (std::filesystem::path(a.output) / study::kStudyReportFile).string(),
               static_cast<double>(report_bytes) / 1e6, Seconds(wall_start));
  }
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
      "--realisations, --methods) trade fidelity for time; docs/demo.md lists the defaults' cost.");
  cmd->add_option("-o,--output", args->output, "output folder (created if needed)")
      ->capture_default_str();
  cmd->add_option("--input", args->input,
                  "a uniformly sampled CSV log of your own instead of the simulation")
      ->check(kInputFile);
  cmd->add_option("--target", args->target,
                  "with --input: the gyro output column (name or 1-based index)");
  cmd->add_option("--temperature", args->temperature, "with --input: the temperature column");
  args->rate_option = BindSetting(
      cmd->add_option("--rate-hz", args->rate_hz,
                      "with --input: sample rate, Hz (default: from a time_s column, else 1)"),
      {"rate_hz"});
  args->units_option = BindSetting(
      cmd->add_option("--units", args->units,
                      "unit of the --input target for the Allan noise terms: dph|dps|rads")
          ->capture_default_str(),
      {"units"});
  cmd->add_option("--seed", args->seed,
                  "seed of the simulation (run A; run B derives its own), decomposition and learners")
      ->capture_default_str()
      ->check(kSeed);
  BindSetting(cmd->add_option("--threads,-j", args->threads, "worker threads (0 = all cores)")
                  ->capture_default_str(),
              {"threads"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "no progress bar and no tables on the terminal");
  BindSetting(
      cmd->add_option("--duration", args->duration,
                      "advanced: length of each simulated run, at least 2h (2h, 150min, 8h)")
          ->capture_default_str()
          ->group("Advanced"),
      {"duration_s"});
  BindSetting(cmd->add_option("--ensemble", args->ensemble, "advanced: BEEMDAN ensemble size")
                  ->capture_default_str()
                  ->group("Advanced"),
              {"ensemble_size"});
  BindSetting(
      cmd->add_option(
             "--realisations", args->realisations,
             "advanced: white-noise realisations of the selection's Monte-Carlo level (>= 20)")
          ->capture_default_str()
          ->group("Advanced"),
      {"realisations"});
  BindSetting(cmd->add_option("--window", args->window,
                              "advanced: trailing window of the causal protocol, samples")
                  ->capture_default_str()
                  ->group("Advanced"),
              {"causal_window"});
  BindSetting(cmd->add_option("--methods", args->methods,
                              "advanced: all, or a list such as ms-elm,elm,poly")
                  ->capture_default_str()
                  ->group("Advanced"),
              {"methods"});
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
