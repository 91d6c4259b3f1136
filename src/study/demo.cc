#include "gyrodrift/study/demo.h"

#include <fmt/core.h>

#include <chrono>
#include <utility>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/common/version.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/study/study_files.h"
#include "gyrodrift/tasks/evaluate_task.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::study {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// `name` as the settings' user types it: "--rate-hz" for flags, "rate_hz" for keys.
std::string Spell(const DemoSettings& s, const std::string& name) {
  if (!tasks::SpeltAsFlags(s.log)) return name;
  std::string flag = "--" + name;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

// A log's settings need the log, and a log needs its two columns.
void RequireInputSettings(const DemoSettings& s) {
  const bool log_given = s.log != io::LogOptions{.gaps_name = s.log.gaps_name};
  if (s.input.empty()) {
    if (!s.target.empty() || !s.temperature.empty() || s.rate_hz ||
        s.units != DemoSettings{}.units || log_given) {
      // Flags: the log options every command takes (AddLogOptions); keys: Python's demo's one.
      const std::string log_settings =
          tasks::SpeltAsFlags(s.log) ? "--gaps and --delimiter" : "and gaps";
      throw UsageError(fmt::format(
          "{}, {}, {}, {}{} {} need {} (the simulated output is in deg/h at 1 Hz)",
          Spell(s, "target"), Spell(s, "temperature"), Spell(s, "rate_hz"), Spell(s, "units"),
          tasks::SpeltAsFlags(s.log) ? "," : "", log_settings, Spell(s, "input")));
    }
    return;
  }
  if (s.target.empty()) {
    throw UsageError(
        fmt::format("{} needs {} (the gyro output column)", Spell(s, "input"), Spell(s, "target")));
  }
  if (s.temperature.empty()) {
    throw UsageError(fmt::format("{} needs {} (compensate mode models drift from temperature)",
                                 Spell(s, "input"), Spell(s, "temperature")));
  }
  if (s.duration_s != DemoSettings{}.duration_s) {
    throw UsageError(
        fmt::format("{} sets the simulated runs' length: a log given by {} is "
                    "studied whole",
                    Spell(s, "duration"), Spell(s, "input")));
  }
  if (s.log.gaps == io::GapPolicy::kSplit || s.log.gaps == io::GapPolicy::kCarry) {
    throw UsageError(fmt::format(
        "{}: demo needs one uniform record (the study decomposes and splits one record): use {} "
        "(the made-up rows then count as data) or {}",
        io::SpellGaps(s.log, s.log.gaps), io::SpellGaps(s.log, io::GapPolicy::kInterpolate),
        io::SpellGaps(s.log, io::GapPolicy::kError)));
  }
}

}  // namespace

StudyOptions DemoSettings::Options() const {
  RequireInputSettings(*this);
  StudyOptions o;
  o.units = allan::RateUnitFromString(units);
  o.methods = tasks::ParseMethods(methods, drift::Mode::kCompensate, Spell(*this, "methods"));
  o.duration_s = duration_s;
  o.ensemble_size = ensemble;
  o.realisations = realisations;
  o.causal = causal;
  o.seed = seed;
  o.Validate();
  ValidateThreads(threads);
  return o;
}

StudyLog ReadDemoLog(const DemoSettings& settings) {
  const auto start = Clock::now();
  RequireInputSettings(settings);
  // A given rate is taken as given (the study checks its range), never replaced by time_s's.
  tasks::TaskLog t = tasks::ReadTaskLog(settings.input, settings.log);
  if (settings.rate_hz) {
    t.rate_hz = *settings.rate_hz;
    t.rate_how = "given";
  } else {
    t.rate_hz = io::ResolveSampleRate(t.table, 0.0, &t.rate_how);
  }
  StudyLog log;
  log.source = settings.input;
  const auto name = [&t](const std::string& column) {
    return t.table.header()[static_cast<size_t>(t.table.ResolveColumn(column))];
  };
  log.target_name = name(settings.target);
  log.temperature_name = name(settings.temperature);
  log.output = t.table.Column(log.target_name);
  log.temperature = t.table.Column(log.temperature_name);
  log.rate_hz = t.rate_hz;
  log.rate_source = tasks::RateSourceText(t.rate_how, tasks::SpeltAsFlags(settings.log));
  for (const std::string* note : {&t.gap_note, &t.time_note}) {
    if (note->empty()) continue;
    log.time_note += (log.time_note.empty() ? "" : "\n") + *note;
  }
  while (!log.time_note.empty() && log.time_note.back() == '\n') log.time_note.pop_back();
  log.read_s = Seconds(start);
  return log;
}

std::vector<double> DemoStageWeights(bool simulated) {
  // Seconds of the default simulated run (2026-11-28, idle 2-core machine: simulate 0.11,
  // decompose + select 1.5, predict 16.3, compensate 10.6, Allan 0.04, writing 0.3) and of the
  // TVAC log of docs/demo.md (measured before the six causal windows).
  return simulated ? std::vector<double>{0.1, 1.5, 16, 11, 0.05, 0.3}
                   : std::vector<double>{0.1, 0.5, 12, 5, 0.1, 1};
}

nlohmann::json DemoRecord(const DemoSettings& s, const StudyResult& result) {
  nlohmann::json record = {{"tool", "gyrodrift"}, {"version", kVersion}, {"command", "demo"}};
  record.update(StudyRecord(result));
  record["options"] = {{"output", s.output},
                       {"input", s.input},
                       {"target", s.target},
                       {"temperature", s.temperature},
                       {"rate_hz", result.rate_hz},
                       {"rate_source", result.rate_source},
                       {"units", s.units},
                       {"duration_s", result.simulated ? result.options.duration_s : 0.0},
                       {"ensemble", s.ensemble},
                       {"realisations", s.realisations},
                       {"window", s.causal.window},
                       {"mirror", s.causal.mirror},
                       {"windows", s.causal.windows},
                       {"methods", s.methods},
                       {"seed", s.seed},
                       {"threads", s.threads}};
  return record;
}

DemoRun RunDemo(const DemoSettings& settings, const StudyContext& context) {
  const auto start = Clock::now();
  // Every mistake before the work (but the range of a log's rate, which the study checks with
  // the log's other data): the options, the folder and the report's scripts.
  const StudyOptions options = settings.Options();
  if (!settings.input.empty()) io::RequireInputsOutsideFolder({settings.input}, settings.output);
  const html::DygraphsAssets assets = html::LoadDygraphs();
  RequireUsableOutputFolder(settings.output);
  DemoRun run;
  if (settings.input.empty()) {
    run.result = RunStudy(options, context);
  } else {
    if (context.progress) context.progress(0, 0.0, "reading " + settings.input);
    run.result = RunStudy(options, ReadDemoLog(settings), context);
  }
  if (context.progress) context.progress(kStudyStages, 0.0, "writing " + settings.output);
  run.files = RenderStudyFiles(run.result, assets);
  run.files.push_back({"demo.json", DemoRecord(settings, run.result).dump(2) + "\n"});
  WriteStudyFiles(settings.output, run.files, {settings.input});
  run.seconds = Seconds(start);
  return run;
}

}  // namespace gyrodrift::study
