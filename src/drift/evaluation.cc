#include "gyrodrift/drift/evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "drift/fit_steps.h"
#include "drift/prediction_steps.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::drift {

std::uint64_t RepeatSeed(std::uint64_t seed, int r) {
  return r == 0 ? seed : SeedFor(seed, "repeat", static_cast<std::uint64_t>(r));
}

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

struct Trial {
  Eigen::VectorXd estimate;  // on the test block
  double train_s = 0.0, predict_s = 0.0;
  std::string summary;
  std::string note;  // CausalWindowNote of a causal trial
};

// Fits and scores one (method, protocol, seed) on the split record.
Trial RunTrial(const Eigen::Ref<const Eigen::VectorXd>& y,
               const Eigen::Ref<const Eigen::MatrixXd>& temperature_c, const DriftOptions& given,
               Protocol protocol, Eigen::Index split, int horizon, const CausalOptions& causal,
               const Execution& windows) {
  const Execution fit{.threads = windows.threads};  // a trial's fit reports nothing
  DriftOptions o = given;
  // The references read no temperature: the first channel serves for the record's length, so
  // that they score beside identified models of several channels.
  if (IsBaseline(o.method) && temperature_c.cols() > 1) {
    return RunTrial(y, Eigen::MatrixXd(temperature_c.leftCols(1)), given, protocol, split, horizon,
                    causal, windows);
  }
  o.features = ForTrainingRecord(o.features, split);  // as FitDriftModel does on the block
  const Eigen::Index n = y.size();
  const Eigen::Index test = n - split;
  const bool thermal_needed = o.uses_temperature();
  Trial trial;
  auto start = std::chrono::steady_clock::now();
  DriftModel model;
  // Paper protocol: the whole record is decomposed (and grouped) before the split. Predict mode
  // only: in compensate mode that would fit the model on the test block's output, which the
  // estimate (from temperature alone) must never see (until 2026-11-27 it did).
  const bool decompose_all =
      protocol == Protocol::kPaper && UsesDecomposition(o.method) && o.mode == Mode::kPredict;
  Eigen::MatrixXd series_all;
  Eigen::MatrixXd thermal_all;
  if (thermal_needed && !IdentifiesThermalModel(o)) {
    thermal_all = ThermalFeatures(temperature_c.col(0), EffectiveFeatures(o));
  } else {
    thermal_all.resize(n, 0);
  }
  if (decompose_all) {
    internal::SubSeries prepared = internal::PrepareSubSeries(y, o, fit);
    series_all = std::move(prepared.series);
    model = std::move(prepared.model);
    internal::FitLearners(model, series_all, y, thermal_all, split,
                          thermal_needed ? Eigen::MatrixXd(temperature_c) : Eigen::MatrixXd(n, 0),
                          {}, fit.threads);
  } else {
    model = FitDriftModel(
        y.head(split),
        thermal_needed ? Eigen::MatrixXd(temperature_c.topRows(split)) : Eigen::MatrixXd(), o, {},
        fit);
  }
  trial.train_s = Seconds(start);
  trial.summary = model.Summary();

  start = std::chrono::steady_clock::now();
  if (o.mode == Mode::kCompensate) {
    // Thermal features are causal recursions: estimating on the whole record and keeping the
    // test block gives the filter states a navigation computer would have.
    trial.estimate = EstimateDrift(model, temperature_c).tail(test);
  } else if (decompose_all) {
    trial.estimate = PredictFromSeries(model, series_all, thermal_all, split, test, horizon);
  } else {
    trial.estimate = PredictAhead(
        model, y, thermal_needed ? Eigen::VectorXd(temperature_c.col(0)) : Eigen::VectorXd(), split,
        horizon, Protocol::kCausal, causal, windows);
  }
  trial.predict_s = Seconds(start);
  // A compensate-mode estimate reads no window of the output.
  if (protocol == Protocol::kCausal && o.mode == Mode::kPredict) {
    trial.note = CausalWindowNote(model, causal);
  }
  return trial;
}

}  // namespace

Metrics ComputeMetrics(const Eigen::Ref<const Eigen::VectorXd>& error) {
  Metrics m;
  if (error.size() == 0) return m;
  m.rmse = std::sqrt(error.squaredNorm() / static_cast<double>(error.size()));
  m.mae = error.cwiseAbs().mean();
  m.max_abs = error.cwiseAbs().maxCoeff();
  return m;
}

void EvaluationOptions::Validate() const {
  RequireInRange("split", split, 0.1, 0.95);
  if (repeats < 1 || repeats > 1000)
    ThrowOption("repeats", std::to_string(repeats), "an integer in [1, 1000]");
  if (methods.empty()) ThrowOption("methods", "(empty)", "at least one method");
  if (protocols.empty()) ThrowOption("protocols", "(empty)", "at least one protocol");
  ValidateNested("causal", [&] { causal.Validate(); });
  internal::RequireHorizon(horizon);
}

std::vector<Method> EvaluatedMethods(const EvaluationOptions& options) {
  std::vector<Method> methods = ReferenceMethods();
  for (Method m : options.methods) {
    if (std::find(methods.begin(), methods.end(), m) == methods.end()) methods.push_back(m);
  }
  return methods;
}

double SlowVariation(const Eigen::Ref<const Eigen::VectorXd>& x, double rate_hz, double block_s) {
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e9);
  RequireInRange("block_s", block_s, 1e-9, 1e12);
  const auto block = std::max<Eigen::Index>(1, std::llround(block_s * rate_hz));
  if (x.size() < block) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::VectorXd means = BlockMeans(x, block);  // compensation_summary.h
  return std::sqrt(means.squaredNorm() / static_cast<double>(means.size()));
}

double SlowVariationRemoved(const Eigen::Ref<const Eigen::VectorXd>& reference,
                            const Eigen::Ref<const Eigen::VectorXd>& estimate, double rate_hz,
                            double block_s) {
  if (reference.size() != estimate.size()) {
    throw DataError("slow variation: the estimate has " + std::to_string(estimate.size()) +
                    " samples, the reference " + std::to_string(reference.size()));
  }
  const double before = SlowVariation(reference, rate_hz, block_s);
  if (!(before > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return 1.0 - SlowVariation(reference - estimate, rate_hz, block_s) / before;
}

namespace {

// Refuses, before any fit, inputs the methods cannot be scored on: a method of another mode, a
// missing, short or non-finite temperature where one is needed (several channels only for
// identified models), a truth of another length or not finite.
void CheckInputs(const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                 const Eigen::Ref<const Eigen::VectorXd>& truth, const DriftOptions& base,
                 const std::vector<Method>& methods) {
  RequireFiniteSignal("target", y, 64);
  const Eigen::Index n = y.size();
  for (Method m : methods) {
    if (!SupportsMode(m, base.mode)) {
      ThrowOption("methods", std::string(ToString(m)),
                  "methods of " + std::string(ToString(base.mode)) + " mode");
    }
  }
  if (base.uses_temperature()) {
    if (temperature_c.rows() != n || temperature_c.cols() < 1) {
      throw DataError(std::string(ToString(base.mode)) + " mode" +
                      (base.features.use_temperature ? " with temperature features" : "") +
                      " needs a temperature column of the same length as the target");
    }
    for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
      RequireFiniteSignal("temperature", temperature_c.col(c), n);
    }
    // Several channels serve only identified models: refused before any fit.
    for (Method method : methods) {
      if (IsBaseline(method)) continue;  // reads no temperature (RunTrial)
      DriftOptions o = base;
      o.method = method;
      internal::RequireChannelsFor(o, temperature_c.cols());
    }
  }
  if (truth.size() != 0) {
    if (truth.size() != n) throw DataError("truth column length differs from the target's");
    RequireFiniteSignal("truth", truth, n);
  }
}

// The first test sample must be predictable with the most lags the fit may choose, under the
// causal protocol's rule (the stricter one): refused before any fit.
void CheckHorizon(const DriftOptions& base, int horizon, Eigen::Index split) {
  if (base.mode != Mode::kPredict || horizon <= 1) return;
  const int lags = base.auto_lags
                       ? *std::max_element(base.lag_candidates.begin(), base.lag_candidates.end())
                       : base.features.lags;
  const Eigen::Index first = internal::FirstPredictable(lags, true, horizon);
  if (split < first) {
    ThrowOption("horizon", std::to_string(horizon),
                "at most " + std::to_string(horizon - (first - split)) +
                    " with the split at sample " + std::to_string(split) +
                    " (the lags and the shortest causal window before the first origin)");
  }
}

// What every trial of one evaluation shares.
struct Trials {
  const Eigen::Ref<const Eigen::VectorXd>& y;
  const Eigen::Ref<const Eigen::MatrixXd>& temperature_c;
  const DriftOptions& base;
  const EvaluationOptions& options;
  const Execution& execution;
  Eigen::Index split;
  const Eigen::VectorXd& reference;  // the test block's scores are against it
  Eigen::VectorXd measured;          // the test block of y
  double total;                      // trials in the evaluation (progress)
};

// The row of `method` under `protocol`: the mean scores of options.repeats trials, seeded
// RepeatSeed(base.seed, r); `done` counts the trials run (progress).
EvaluationRow ScoreRow(const Trials& t, Method method, Protocol protocol, double& done) {
  const int repeats = t.options.repeats;
  EvaluationRow row;
  row.method = method;
  row.protocol = protocol;
  std::vector<double> rmse;
  for (int r = 0; r < repeats; ++r) {
    DriftOptions o = t.base;
    o.method = method;
    o.seed = RepeatSeed(t.base.seed, r);
    const std::string label = std::string(ToString(method)) + " / " +
                              std::string(ToString(protocol)) + " / seed " + std::to_string(o.seed);
    t.execution.Report(done / t.total, label);
    Execution windows{.threads = t.execution.threads};
    if (t.execution.progress) {
      // The causal trial's windows are most of an evaluation's time: report within it too.
      windows.progress = [&execution = t.execution, done, total = t.total,
                          label = label + " / windows"](double fraction, std::string_view) {
        execution.progress((done + fraction) / total, label);
      };
    }
    const Trial trial = RunTrial(t.y, t.temperature_c, o, protocol, t.split, t.options.horizon,
                                 t.options.causal, windows);
    const Metrics m = ComputeMetrics(trial.estimate - t.reference);
    rmse.push_back(m.rmse);
    row.mae += m.mae / repeats;
    row.max_abs += m.max_abs / repeats;
    row.rmse_measured += ComputeMetrics(trial.estimate - t.measured).rmse / repeats;
    row.slow_removed +=
        SlowVariationRemoved(t.reference, trial.estimate, t.base.features.rate_hz) / repeats;
    row.train_s += trial.train_s / repeats;
    row.predict_s += trial.predict_s / repeats;
    row.estimate = trial.estimate;
    row.model_summary = trial.summary;
    if (!trial.note.empty())
      row.notes.push_back("seed " + std::to_string(o.seed) + ": " + trial.note);
    done += 1;
  }
  double mean = 0;
  for (double v : rmse) mean += v / static_cast<double>(rmse.size());
  double var = 0;
  for (double v : rmse) var += (v - mean) * (v - mean);
  row.rmse = mean;
  row.rmse_std = rmse.size() > 1 ? std::sqrt(var / static_cast<double>(rmse.size() - 1)) : 0.0;
  return row;
}

}  // namespace

EvaluationResult Evaluate(const Eigen::Ref<const Eigen::VectorXd>& y,
                          const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                          const Eigen::Ref<const Eigen::VectorXd>& truth, const DriftOptions& base,
                          const EvaluationOptions& options, const Execution& execution) {
  base.Validate();
  options.Validate();
  execution.Validate();
  if (base.mode == Mode::kCompensate && options.horizon != 1) {
    ThrowOption("horizon", std::to_string(options.horizon),
                "1 in compensate mode (the estimate at t is read from the temperature, not "
                "predicted ahead)");
  }
  const std::vector<Method> methods = EvaluatedMethods(options);
  CheckInputs(y, temperature_c, truth, base, methods);
  const Eigen::Index n = y.size();
  EvaluationResult result;
  result.mode = base.mode;
  result.split_index =
      static_cast<Eigen::Index>(std::floor(options.split * static_cast<double>(n)));
  const Eigen::Index split = result.split_index;
  if (split < 32 || n - split < 16) {
    throw DataError("split at sample " + std::to_string(split) + " of " + std::to_string(n) +
                    " leaves too little data (at least 32 training and 16 test samples)");
  }
  CheckHorizon(base, options.horizon, split);
  // Named as the training block: the fits see only it, and the whole record may vary.
  const std::string block = "'s training block (samples 1.." + std::to_string(split) + ")";
  RequireVaryingSignal("target" + block, y.head(split), "there is nothing to fit the methods on");
  if (base.uses_temperature()) {
    for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
      RequireVaryingSignal("temperature" + block, temperature_c.col(c).head(split),
                           "a drift model on temperature needs a training block whose "
                           "temperature changes");
    }
  }
  if (temperature_c.rows() == n && temperature_c.cols() > 0) {
    const auto t = temperature_c.col(0);
    result.training_temperature_min_c = t.head(split).minCoeff();
    result.training_temperature_max_c = t.head(split).maxCoeff();
    result.test_outside_training_temperature_share = ShareOutsideRange(
        t.tail(n - split), result.training_temperature_min_c, result.training_temperature_max_c);
  }
  result.against_truth = truth.size() != 0;
  result.reference = result.against_truth ? Eigen::VectorXd(truth.tail(n - split))
                                          : Eigen::VectorXd(y.tail(n - split));
  const Trials trials{y,
                      temperature_c,
                      base,
                      options,
                      execution,
                      split,
                      result.reference,
                      y.tail(n - split),
                      static_cast<double>(methods.size() * options.protocols.size() *
                                          static_cast<size_t>(options.repeats))};
  double done = 0;
  for (Method method : methods) {
    // Single models never decompose, and in compensate mode nothing is decomposed past the
    // training block: both protocols are the same computation, run once.
    const bool one_computation = !UsesDecomposition(method) || base.mode == Mode::kCompensate;
    std::vector<EvaluationRow> computed;
    for (Protocol protocol : options.protocols) {
      if (one_computation && !computed.empty()) {
        EvaluationRow row = computed.front();
        row.protocol = protocol;
        result.rows.push_back(row);
        done += options.repeats;
        continue;
      }
      computed.push_back(ScoreRow(trials, method, protocol, done));
      result.rows.push_back(computed.back());
    }
  }
  execution.Report(1.0, "done");
  return result;
}

std::string EvaluationResult::Table() const {
  std::string out;
  char line[320];
  std::snprintf(line, sizeof(line), "%-13s %-8s %12s %12s %12s %12s %13s %8s %9s %10s\n", "method",
                "protocol", "rmse", "rmse_std", "mae", "max_abs", "rmse_measured", "slow_rm",
                "train_s", "predict_s");
  out += line;
  for (const auto& r : rows) {
    char slow[32] = "-";  // shorter than one 10-min block
    if (std::isfinite(r.slow_removed)) {
      std::snprintf(slow, sizeof(slow), "%.1f%%", 100.0 * r.slow_removed);
    }
    std::snprintf(
        line, sizeof(line), "%-13s %-8s %12.6g %12.3g %12.6g %12.6g %13.6g %8s %9.3f %10.3f\n",
        std::string(ToString(r.method)).c_str(), std::string(ToString(r.protocol)).c_str(), r.rmse,
        r.rmse_std, r.mae, r.max_abs, r.rmse_measured, slow, r.train_s, r.predict_s);
    out += line;
  }
  return out;
}

}  // namespace gyrodrift::drift
