// The study's steps: data, decomposition, predict mode, compensate mode, Allan deviation.
#include "gyrodrift/study/study.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/tasks/compensate_task.h"
#include "gyrodrift/tasks/evaluate_task.h"
#include "gyrodrift/tasks/fit_task.h"
#include "study_steps.h"

namespace gyrodrift::study {

std::uint64_t RunBSeed(std::uint64_t seed) { return SeedFor(seed, "run-b"); }

namespace {

namespace sim = gyrodrift::simulation;
namespace dec = gyrodrift::decomposition;
namespace sel = gyrodrift::selection;
using Clock = std::chrono::steady_clock;

constexpr double kMinDurationS = 2 * 3600.0;
// A 70/30 split with 32 training and 16 test samples, and room for the decomposition.
constexpr Eigen::Index kMinLogSamples = 64;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

double Rms(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return v.size() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.size())) : 0.0;
}

std::string UnitText(allan::RateUnit unit) {
  switch (unit) {
    case allan::RateUnit::kDegPerHour:
      return "deg/h";
    case allan::RateUnit::kDegPerSecond:
      return "deg/s";
    case allan::RateUnit::kRadPerSecond:
      return "rad/s";
  }
  return "deg/h";
}

// The context's calls, each of which may be empty.
struct Notifier {
  const StudyContext& context;
  void Progress(int stage, double fraction, const std::string& what) const {
    if (context.progress) context.progress(stage, fraction, what);
  }
  void StageDone(int stage, const std::string& summary) const {
    if (context.stage_done) context.stage_done(stage, summary);
  }
};

// Evaluate reports the share of its trials done; the trials differ in cost by orders of magnitude
// (a causal MS-ELM trial decomposes windows for every test sample), so the trial index is mapped
// to a share of the expected cost instead. Weights: measured shares of the default demo
// (2026-11-28: a decomposing method's causal trial about 4.5 s, its paper trial 1.5 s).
std::function<void(double, std::string_view)> TrialProgress(
    const Notifier& notify, int stage, const std::vector<drift::Method>& methods, drift::Mode mode,
    const std::string& prefix) {
  const std::vector<drift::Protocol> protocols{drift::Protocol::kPaper, drift::Protocol::kCausal};
  std::vector<double> cumulative{0.0};
  for (drift::Method m : methods) {
    for (drift::Protocol p : protocols) {
      double w = 0.0;
      if (drift::UsesDecomposition(m)) {
        w = p == drift::Protocol::kCausal && mode == drift::Mode::kPredict ? 4.5 : 1.5;
      } else if (p == drift::Protocol::kPaper) {
        w = 0.5;  // the causal row of a single model is a copy
      }
      cumulative.push_back(cumulative.back() + w);
    }
  }
  return [notify, stage, cumulative, prefix](double fraction, std::string_view label) {
    const double trials = static_cast<double>(cumulative.size() - 1);
    const size_t i =
        std::min(cumulative.size() - 1, static_cast<size_t>(std::lround(fraction * trials)));
    notify.Progress(stage, cumulative[i] / cumulative.back(), prefix + std::string(label));
  };
}

// A compensate-mode model of `method` fitted on (y, temperature) through the fit task, as
// `gyrodrift fit` fits it.
drift::DriftModel FitCompensation(const StudyResult& s, drift::Method method,
                                  const Eigen::VectorXd& y, const Eigen::VectorXd& temperature) {
  tasks::FitRun run{.targets = {"y"}, .temperatures = {"temperature"}};
  Eigen::MatrixXd rows(y.size(), 2);
  rows << y, temperature;
  run.rows.Append(rows);
  drift::FitSettings settings = internal::StudyFitSettings(s, drift::Mode::kCompensate);
  settings.method = std::string(drift::ToString(method));
  return tasks::RunFit(run, settings, "dph").axes.front().model;
}

// The study's evaluation of `methods` ("all" or a comma-separated list) with the models' settings
// `fit`: the causal protocol's windows are the study's.
tasks::EvaluateSettings EvaluationSettings(const StudyOptions& a, drift::FitSettings fit,
                                           std::string methods) {
  return {.fit = std::move(fit), .methods = std::move(methods), .causal = a.causal};
}

// `methods` scored in `mode` on the record through the evaluate task (against `truth` when not
// empty), reporting to stage `stage` of the context.
drift::EvaluationResult EvaluateStep(const StudyResult& s, drift::Mode mode,
                                     const std::vector<drift::Method>& methods,
                                     const Eigen::VectorXd& truth, const Notifier& notify,
                                     int stage, const std::string& prefix) {
  std::string list;
  for (drift::Method m : methods)
    list += (list.empty() ? "" : ",") + std::string(drift::ToString(m));
  const tasks::EvaluateSettings settings =
      EvaluationSettings(s.options, internal::StudyFitSettings(s, mode), list);
  auto progress =
      TrialProgress(notify, stage, drift::EvaluatedMethods(settings.Options()), mode, prefix);
  return tasks::RunEvaluate(s.output, s.temperature, truth, settings, std::move(progress)).result;
}

void SimulateRuns(const StudyOptions& a, StudyResult& s) {
  const sim::FogParameters fog = sim::PresetParameters(sim::Preset::kNavigation);
  sim::SimulationOptions so;
  so.duration_s = a.duration_s;
  so.rate_hz = 1.0;
  so.seed = a.seed;
  s.run_a = sim::Simulate(sim::BuiltinProgramme("chamber"), fog, so);
  so.seed = RunBSeed(a.seed);
  s.run_b = sim::Simulate(sim::BuiltinProgramme("chamber-b"), fog, so);
  s.source = "simulation";
  s.target_name = "rate_dph";
  s.unit = "deg/h";
  s.temperature_name = "temperature_c";
  s.rate_hz = so.rate_hz;
  s.rate_source = "simulated";
  s.output = s.run_a.rate_dph;
  s.temperature = s.run_a.temperature_c;
  s.truth = s.run_a.drift_dph;
  s.time_h = s.run_a.time_s / 3600.0;
}

void TakeLog(const StudyOptions& a, const StudyLog& log, StudyResult& s) {
  s.output = log.output;
  s.temperature = log.temperature;
  s.source = log.source;
  s.target_name = log.target_name;
  s.unit = UnitText(a.units);
  s.temperature_name = log.temperature_name;
  s.rate_hz = log.rate_hz;
  s.rate_source = log.rate_source;
  s.time_note = log.time_note;
  s.time_h =
      Eigen::VectorXd::LinSpaced(s.output.size(), 0.0, static_cast<double>(s.output.size() - 1)) /
      (3600.0 * s.rate_hz);
}

void DecomposeStep(StudyResult& s) {
  const StudyOptions& a = s.options;
  // One seed for both, as FitDriftModel seeds them: the selection's white-noise level draws its
  // own realisations when the ensemble is smaller than the Monte-Carlo (issue 25).
  dec::DecompositionOptions dopt = s.drift_options.decomposition;
  dopt.seed = a.seed;
  sel::SelectionOptions sopt = s.drift_options.selection;
  sopt.monte_carlo.seed = a.seed;
  dec::DecompositionContext context;
  context.execution.threads = s.threads;
  sel::GroupedDecomposition grouped = sel::DecomposeAndSelect(s.output, dopt, sopt, context);
  if (!grouped.selection) {
    throw DataError(s.target_name +
                    " has fewer than 3 extrema: there is nothing to decompose or to model");
  }
  s.decomposition = std::move(grouped.decomposition);
  s.selection = std::move(*grouped.selection);
}

void PredictStep(StudyResult& s, const Notifier& notify) {
  std::vector<drift::Method> methods;
  for (drift::Method m : s.options.methods) {
    if (drift::SupportsMode(m, drift::Mode::kPredict)) methods.push_back(m);
  }
  // The filters of the measured output a reviewer compares MS-ELM with (predict mode only, so not
  // among the study's methods, which are compensate mode's): cheap, always shown.
  for (drift::Method m : drift::AllMethods(drift::Mode::kPredict)) {
    if (drift::IsBaseline(m) && std::find(methods.begin(), methods.end(), m) == methods.end()) {
      methods.push_back(m);
    }
  }
  s.predict = EvaluateStep(s, drift::Mode::kPredict, methods, s.truth, notify, 2, "predict: ");
}

void CompensateSimulated(StudyResult& s, const Notifier& notify) {
  // The references first, as every evaluation shows them (no model files: nothing to deploy).
  drift::EvaluationOptions e;
  e.methods = s.options.methods;
  const std::vector<drift::Method> methods = drift::EvaluatedMethods(e);
  s.compensate_reference = s.run_b.drift_dph;
  s.compensate_output = s.run_b.rate_dph;
  s.compensate_time_h = s.run_b.time_s / 3600.0;
  const double reference_rms = Rms(s.compensate_reference);
  for (size_t i = 0; i < methods.size(); ++i) {
    notify.Progress(3, static_cast<double>(i) / static_cast<double>(methods.size()),
                    "compensate: " + std::string(drift::ToString(methods[i])));
    StudyResult::CompensateRow row{methods[i], "train A test B", {}, 0.0, 0.0, 0.0, {}, {}};
    auto start = Clock::now();
    const io::LoadedModel loaded{
        FitCompensation(s, methods[i], s.run_a.rate_dph, s.run_a.temperature_c),
        {"rate_dph", "temperature_c", "simulation run A (chamber)", "", "dph"}};
    row.train_s = Seconds(start);
    start = Clock::now();
    // Through the compensate task, as `gyrodrift compensate` applies the model file to run B.
    row.estimate =
        tasks::CompensateAxis(loaded, s.run_b.rate_dph, s.run_b.temperature_c, {}, {}, {}).estimate;
    row.estimate_s = Seconds(start);
    row.metrics = drift::ComputeMetrics(s.compensate_reference - row.estimate);
    row.share_removed = 1.0 - row.metrics.rmse / reference_rms;
    row.summary = loaded.model.Summary();
    row.slow_removed = drift::SlowVariationRemoved(s.compensate_reference, row.estimate, s.rate_hz);
    if (!drift::IsBaseline(methods[i])) {
      s.model_files.push_back(
          {"models/" + std::string(drift::ToString(methods[i])) + "_compensate.json",
           io::RenderModelFile({loaded})});
    }
    s.compensate.push_back(std::move(row));
  }
}

void CompensateSplit(StudyResult& s, const Notifier& notify) {
  const std::vector<drift::Method>& methods = s.options.methods;
  s.compensate_split = EvaluateStep(s, drift::Mode::kCompensate, methods, Eigen::VectorXd(), notify,
                                    3, "compensate: ");
  const Eigen::Index split = s.compensate_split.split_index;
  s.compensate_reference = s.compensate_split.reference;
  s.compensate_output = s.output.tail(s.output.size() - split);
  s.compensate_time_h = s.time_h.tail(s.output.size() - split);
  // The measured output carries the sensor's constant bias, which any model removes; the share is
  // taken of the output's variation about its mean instead.
  const double reference_rms = Rms(s.compensate_reference.array() - s.compensate_reference.mean());
  for (const auto& r : s.compensate_split.rows) {
    StudyResult::CompensateRow row{r.method,   std::string(drift::ToString(r.protocol)),
                                   {},         0.0,
                                   r.train_s,  r.predict_s,
                                   r.estimate, r.model_summary};
    row.metrics = drift::ComputeMetrics(s.compensate_reference - r.estimate);
    row.share_removed = 1.0 - row.metrics.rmse / reference_rms;
    row.slow_removed = r.slow_removed;
    s.compensate.push_back(std::move(row));
  }
  // Models for the files: fitted on the whole record (what a user would deploy).
  for (drift::Method m : methods) {
    const drift::DriftModel model = FitCompensation(s, m, s.output, s.temperature);
    // gyrodrift compensate reads the temperature from the column named here.
    io::ModelFileInfo info{s.target_name, s.temperature_name, s.source, "",
                           std::string(allan::ToString(s.options.units))};
    s.model_files.push_back({"models/" + std::string(drift::ToString(m)) + "_compensate.json",
                             io::RenderModelFile(model, info)});
  }
}

void AllanStep(StudyResult& s) {
  // The compensated output: MS-ELM if it ran (causal row for a split), else the first method
  // that is not a reference.
  const StudyResult::CompensateRow* best = nullptr;
  for (const auto& r : s.compensate) {
    if (r.method == drift::Method::kMsElm && (r.protocol != "paper")) best = &r;
  }
  for (const auto& r : s.compensate) {
    if (!best && !drift::IsBaseline(r.method)) best = &r;
  }
  if (!best && !s.compensate.empty()) best = &s.compensate.front();
  s.compensated_by =
      best ? std::string(drift::ToString(best->method)) + " (" + best->protocol + ")" : "";
  const StudyResult::CompensateRow* lowest = nullptr;
  for (const auto& r : s.compensate) {
    if (r.protocol != "paper" && (!lowest || r.metrics.rmse < lowest->metrics.rmse)) lowest = &r;
  }
  // Another method only when it is clearly better (linear sub-models of MS-ELM and EMD-ELM can sum
  // to the same estimate).
  if (lowest == best || (best && lowest && lowest->metrics.rmse > 0.99 * best->metrics.rmse))
    lowest = nullptr;
  if (lowest)
    s.best_by = std::string(drift::ToString(lowest->method)) + " (" + lowest->protocol + ")";
  allan::AllanOptions o;
  o.rate_hz = s.rate_hz;
  o.units = s.options.units;
  const Execution execution{.threads = s.threads};
  s.allan_raw = allan::Compute(s.compensate_output, o, execution);
  if (best) {
    s.allan_compensated =
        allan::Compute(Eigen::VectorXd(s.compensate_output - best->estimate), o, execution);
  }
  if (lowest) {
    s.allan_best =
        allan::Compute(Eigen::VectorXd(s.compensate_output - lowest->estimate), o, execution);
  }
  if (s.simulated) s.allan_noise = allan::Compute(s.run_b.noise_dph, o, execution);
  // The noise terms are in deg/h; a curve too short to fit is reported, not fatal.
  auto fit = [&](const allan::AllanResult& r, std::optional<allan::NoiseTerms>& out) {
    if (r.points.empty()) return;
    try {
      allan::AllanResult converted = r;
      const double to_dph = allan::ToDegPerHour(o.units);
      for (auto& p : converted.points) {
        p.dev *= to_dph;
        p.dev_lo *= to_dph;
        p.dev_hi *= to_dph;
      }
      converted.options.units = allan::RateUnit::kDegPerHour;
      out = allan::IdentifyNoise(converted);
    } catch (const Error& e) {
      s.terms_note += std::string(e.what()) + "; ";
    }
  };
  fit(s.allan_raw, s.terms_raw);
  fit(s.allan_compensated, s.terms_compensated);
  fit(s.allan_best, s.terms_best);
  if (s.simulated) fit(s.allan_noise, s.terms_noise);
}

// Refuses a log the study cannot analyse, before any work.
void CheckLog(const StudyOptions& options, const StudyLog& log) {
  if (!log.target_name.empty() && log.target_name == log.temperature_name) {
    throw UsageError("temperature column '" + log.temperature_name +
                     "' is the target column: they must differ");
  }
  ValidateAsSettings({{"features.rate_hz", "rate_hz"}},
                     [&] { internal::StudyDriftOptions(options, log.rate_hz, false).Validate(); });
  if (log.output.size() < kMinLogSamples) {
    throw DataError(log.source + ": " + std::to_string(log.output.size()) +
                    " samples; the study needs at least 64 (a 70/30 split with 32 training and "
                    "16 test samples, and room for the decomposition)");
  }
  if (log.temperature.size() != log.output.size()) {
    throw DataError(log.source + ": the temperature has " + std::to_string(log.temperature.size()) +
                    " samples, the output " + std::to_string(log.output.size()) +
                    ": one per output sample expected");
  }
}

// Records how long the stage `name` took since t0 (plus extra_s spent before the study).
void TimeStage(StudyResult& s, const std::string& name, Clock::time_point t0,
               double extra_s = 0.0) {
  s.stage_s.push_back({name, extra_s + Seconds(t0)});
}

// Stage 1: runs A and B simulated, or the log taken; then the study's drift options.
void DataStage(StudyResult& s, const StudyLog* log, const Notifier& notify) {
  notify.Progress(0, 0.0, s.simulated ? "simulating runs A and B" : "checking " + log->source);
  const auto t0 = Clock::now();
  if (s.simulated) {
    SimulateRuns(s.options, s);
  } else {
    TakeLog(s.options, *log, s);
  }
  s.drift_options = internal::StudyDriftOptions(s.options, s.rate_hz, s.simulated);
  TimeStage(s, s.simulated ? "simulate A and B" : "read", t0, log ? log->read_s : 0.0);
  if (s.simulated) {
    notify.StageDone(0, fmt::format("1. simulated run A: {}\n   simulated run B: {}\n",
                                    s.run_a.Summary(), s.run_b.Summary()));
  } else {
    notify.StageDone(
        0, fmt::format("1. read {}: {} samples of {} at {} Hz ({})\n", s.source, s.output.size(),
                       s.target_name, RoundedText(s.rate_hz), s.rate_source) +
               (s.time_note.empty() ? "" : "   " + s.time_note + "\n"));
  }
}

// The study's steps in order, each reported to the context as it ends.
StudyResult Run(const StudyOptions& options, const StudyLog* log, const StudyContext& context) {
  options.Validate();
  ValidateThreads(context.threads);
  if (log) CheckLog(options, *log);
  const auto start = Clock::now();
  const double read_s = log ? log->read_s : 0.0;
  const Notifier notify{context};
  StudyResult s;
  s.options = options;
  s.threads = context.threads;
  s.simulated = log == nullptr;
  DataStage(s, log, notify);

  notify.Progress(1, 0.0, "BEEMDAN decomposition and mode selection");
  auto t0 = Clock::now();
  DecomposeStep(s);
  TimeStage(s, "decompose + select", t0);
  notify.StageDone(
      1, fmt::format("2. {}\n   {}\n", s.decomposition.report.Summary(), s.selection.Summary()));

  notify.Progress(2, 0.0, "predict mode");
  t0 = Clock::now();
  PredictStep(s, notify);
  TimeStage(s, "predict mode (both protocols)", t0);
  internal::FillPredictTable(s);
  notify.StageDone(2, "3. " + s.predict_table.Text());

  notify.Progress(3, 0.0, "compensate mode");
  t0 = Clock::now();
  if (s.simulated) {
    CompensateSimulated(s, notify);
  } else {
    CompensateSplit(s, notify);
  }
  TimeStage(s, "compensate mode", t0);
  internal::FillCompensateTable(s);
  notify.StageDone(3, "4. " + s.compensate_table.Text());

  notify.Progress(4, 0.0, "Allan deviation");
  t0 = Clock::now();
  AllanStep(s);
  TimeStage(s, "Allan deviation + noise fits", t0);
  internal::FillNoiseTermsTable(s);
  notify.StageDone(4, "5. " + s.terms_table.Text());

  internal::FillSettingsTable(s);
  internal::FillTimingTable(s, read_s + Seconds(start));
  return s;
}

}  // namespace

namespace internal {

drift::DriftOptions StudyDriftOptions(const StudyOptions& options, double rate_hz, bool simulated) {
  drift::DriftOptions o;
  o.decomposition.ensemble_size = options.ensemble_size;
  o.selection.monte_carlo.realisations = options.realisations;
  o.features.rate_hz = rate_hz;
  o.seed = options.seed;
  if (simulated) o.reference_c = 20.0;
  return o;
}

drift::FitSettings StudyFitSettings(const StudyResult& s, drift::Mode mode) {
  const StudyOptions& a = s.options;
  const bool compensate = mode == drift::Mode::kCompensate;
  return {.mode = std::string(drift::ToString(mode)),
          .rate_hz = s.rate_hz,
          .ensemble = a.ensemble_size,
          .realisations = a.realisations,
          .seed = a.seed,
          .threads = s.threads,
          // A compensate-mode setting: the estimate's reference (StudyDriftOptions).
          .reference_temperature = compensate ? s.drift_options.reference_c : std::nullopt,
          .has_temperature = compensate};
}

std::string GroupOf(const sel::SelectionResult& selection, int k) {
  for (const auto& g : selection.groups) {
    if (std::find(g.imfs.begin(), g.imfs.end(), k) != g.imfs.end())
      return std::string(sel::ToString(g.kind));
  }
  return "drift";
}

}  // namespace internal

void StudyOptions::Validate() const {
  // Ranges the library owns are its own Validate's, one home; a refusal names the study's field
  // that set it.
  ValidateAsSettings({{"decomposition.ensemble_size", "ensemble_size"},
                      {"selection.monte_carlo.realisations", "realisations"}},
                     [&] {
                       internal::StudyDriftOptions(*this, 1.0, true).Validate();
                       // The causal protocol's settings; the study's method list is checked
                       // below by its own rule.
                       EvaluationSettings(*this, {.mode = "predict"}, "all").Validate();
                     });
  if (!(duration_s >= kMinDurationS)) {
    ThrowOption("duration_s", FormatValue(duration_s),
                "at least 2h (run A needs a ramp and a dwell)");
  }
  if (methods.empty()) ThrowOption("methods", "(empty)", "at least one method");
  for (auto m = methods.begin(); m != methods.end(); ++m) {
    if (std::find(methods.begin(), m, *m) != m) {
      ThrowOption("methods", std::string(drift::ToString(*m)) + " twice",
                  "a list without repeats (each method saves one model file)");
    }
  }
}

StudyResult RunStudy(const StudyOptions& options, const StudyContext& context) {
  return Run(options, nullptr, context);
}

StudyResult RunStudy(const StudyOptions& options, const StudyLog& log,
                     const StudyContext& context) {
  return Run(options, &log, context);
}

}  // namespace gyrodrift::study
