// FitDriftModel and the steps it is made of (fit_steps.h): the checks of the temperature input,
// the decomposition and grouping into sub-series (PrepareSubSeries; the decomposing methods' own
// steps are in ms_elm.cc and emd_elm.cc), and one learner or identified thermal model per
// sub-series (FitLearners), with the automatic choice of lags.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "drift/fit_steps.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/records.h"

namespace gyrodrift::drift {
namespace internal {

Eigen::MatrixXd PredictRows(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& s,
                            const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index first,
                            Eigen::Index count) {
  Eigen::MatrixXd x(count, model.lags + thermal.cols());
  x.leftCols(model.lags) = LagRows(s, model.lags, first, count);
  if (thermal.cols() > 0) x.rightCols(thermal.cols()) = thermal.middleRows(first - 1, count);
  return x;
}

std::uint64_t SubModelSeed(const DriftOptions& o, size_t g) {
  return SeedFor(o.seed, "sub-model", g);
}

LearnerOptions SubModelLearner(const DriftOptions& o, size_t g) {
  LearnerOptions l = o.learner;
  l.kind = KindOf(o.method);
  l.seed = SubModelSeed(o, g);
  return l;
}

LearnerKind KindOf(Method method) {
  switch (method) {
    case Method::kPoly:
      return LearnerKind::kPoly;
    case Method::kSvr:
      return LearnerKind::kSvr;
    case Method::kBp:
      return LearnerKind::kBp;
    default:
      return LearnerKind::kElm;
  }
}

void RequireTemperatureFor(const Eigen::Ref<const Eigen::MatrixXd>& temperature_c, Eigen::Index n) {
  if (temperature_c.cols() < 1) throw DataError("temperature has no column: give at least one");
  if (temperature_c.rows() != n) {
    throw DataError("temperature has " + std::to_string(temperature_c.rows()) +
                    " samples, the target " + std::to_string(n) + ": they must match");
  }
  for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
    RequireFiniteSignal("temperature", temperature_c.col(c), n);
  }
}

void RequireChannelsFor(const DriftOptions& o, Eigen::Index channels) {
  if (channels <= 1 || IdentifiesThermalModel(o)) return;
  ThrowOption("temperature", std::to_string(channels) + " channels",
              "one for method " + std::string(ToString(o.method)) + " in " +
                  std::string(ToString(o.mode)) +
                  " mode (several channels: compensate mode with thermal, ms-elm or emd-elm)");
}

Eigen::MatrixXd ThermalOrEmpty(const DriftModel& model,
                               const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                               Eigen::Index n) {
  if (!model.uses_temperature() || IdentifiesThermalModel(model.options)) {
    return Eigen::MatrixXd(n, 0);
  }
  RequireTemperatureFor(temperature_c, n);
  internal::RequireChannelsFor(model.options, temperature_c.cols());
  return ThermalFeatures(temperature_c.col(0), EffectiveFeatures(model.options));
}

SubSeries PrepareSubSeries(const Eigen::Ref<const Eigen::VectorXd>& y, const DriftOptions& o,
                           const Execution& execution) {
  SubSeries out;
  out.model.options = o;
  if (!UsesDecomposition(o.method)) {
    out.model.sub_models.push_back({"signal", {}, true, nullptr});
    out.series = y;
    return out;
  }
  decomposition::DecompositionOptions dopt = o.decomposition;
  dopt.seed = o.seed;
  decomposition::DecompositionContext context;
  context.execution.threads = execution.threads;
  if (execution.progress) {
    execution.progress(0.0, "decompose");
    context.execution.progress = [&execution](double fraction, std::string_view) {
      execution.progress(kDecomposeShare * fraction, "decompose");
    };
  }
  const decomposition::Decomposition d =
      o.method == Method::kEmdElm ? DecomposeForEmdElm(y, dopt, context, out.model)
                                  : DecomposeForMsElm(y, dopt, context, out.model);
  out.model.training_imfs = d.num_imfs();
  out.model.decomposition_summary = d.report.Summary();
  if (d.num_imfs() == 0) out.model.sub_models.push_back({"signal", {}, true, nullptr});
  out.series = GroupSeries(out.model, d);
  return out;
}

void FitLearners(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                 const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                 const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                 const std::vector<Eigen::Index>& record_starts, int threads,
                 const std::vector<bool>& logged) {
  const DriftOptions& o = model.options;
  assert(logged.empty() || (o.mode == Mode::kCompensate &&
                            static_cast<Eigen::Index>(logged.size()) == fit_end));
  const Execution learners{.threads = threads};
  model.training_samples = CountLogged(logged, fit_end);  // the samples fitted, not the grid's
  const size_t groups = model.sub_models.size();
  if (IdentifiesThermalModel(o)) {
    // Every sub-series chooses its own thermal states: fast rate terms for the noise and mixed
    // groups, slow levels for the drift group, if the data say so.
    for (size_t g = 0; g < groups; ++g) {
      model.sub_models[g].thermal = std::make_shared<const ThermalRegression>(
          IdentifyThermalModel(temperature_c.topRows(fit_end),
                               series.col(static_cast<Eigen::Index>(g)).head(fit_end),
                               o.features.rate_hz, o.thermal,
                               {.record_starts = record_starts,
                                .logged = logged,
                                .nonlinear = !o.linear_compensation,
                                .seed = SubModelSeed(o, g)}));
    }
    return;
  }
  if (o.mode == Mode::kCompensate) {  // a single learner on the thermal features
    // The features ran over every row (made-up ones too); the fit sees the logged rows only.
    model.sub_models.front().learner =
        FitLearner(LoggedRows(thermal.topRows(fit_end), logged),
                   LoggedRows(series.col(0).head(fit_end), logged), SubModelLearner(o, 0),
                   learners);
    return;
  }
  auto fit_with_lags = [&](int p, Eigen::Index end) {
    model.lags = p;
    if (end - p < 8) {
      throw DataError("training block of " + std::to_string(end) + " samples is too short for " +
                      std::to_string(p) + " lags (at least " + std::to_string(p + 8) + " needed)");
    }
    for (size_t g = 0; g < groups; ++g) {
      const auto s = series.col(static_cast<Eigen::Index>(g));
      model.sub_models[g].learner =
          FitLearner(PredictRows(model, s, thermal, p, end - p), s.segment(p, end - p),
                     SubModelLearner(o, g), learners);
    }
  };
  if (!o.auto_lags) {
    fit_with_lags(o.features.lags, fit_end);
    if (o.method == Method::kMsElm)
      PredictWhiteGroupByMean(model, series, thermal, fit_end, learners);
    return;
  }
  const Eigen::Index validation =
      static_cast<Eigen::Index>(std::floor(o.validation_fraction * fit_end));
  const Eigen::Index inner_end = fit_end - validation;
  double best = std::numeric_limits<double>::infinity();
  int best_p = o.lag_candidates.front();
  model.lag_validation_rmse.clear();
  for (int p : o.lag_candidates) {
    fit_with_lags(p, inner_end);
    const Eigen::VectorXd pred = PredictFromSeries(model, series, thermal, inner_end, validation);
    const double rmse =
        std::sqrt((pred - y.segment(inner_end, validation)).squaredNorm() / validation);
    model.lag_validation_rmse.push_back(rmse);
    if (rmse < best) {
      best = rmse;
      best_p = p;
    }
  }
  fit_with_lags(best_p, fit_end);
  if (o.method == Method::kMsElm)
    PredictWhiteGroupByMean(model, series, thermal, fit_end, learners);
}

}  // namespace internal

DriftModel FitDriftModel(const Eigen::Ref<const Eigen::VectorXd>& y,
                         const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                         const DriftOptions& options,
                         const std::vector<Eigen::Index>& record_starts,
                         const Execution& execution, const std::vector<bool>& logged) {
  options.Validate();
  execution.Validate();
  if (!logged.empty() && (options.mode != Mode::kCompensate || UsesDecomposition(options.method))) {
    throw UsageError(
        "a log whose gaps were filled, fitted on its logged rows only, needs compensate mode and a "
        "method without a decomposition (thermal, poly, elm, svr, bp): method " +
        std::string(ToString(options.method)) + " in " + std::string(ToString(options.mode)) +
        " mode would " +
        (options.mode == Mode::kCompensate ? "decompose across the made-up rows"
                                           : "predict from made-up rows"));
  }
  if (!record_starts.empty() &&
      !(options.mode == Mode::kCompensate && options.method == Method::kThermal)) {
    throw UsageError(
        "several records (calibration logs, or a log split at its gaps) are fitted by method "
        "thermal in compensate mode only: method " + std::string(ToString(options.method)) +
        " in " + std::string(ToString(options.mode)) +
        " mode needs one uniform record (decompositions and lags run across a break)");
  }
  CheckLogged(logged, y.size());
  RequireFiniteLogged("target", y, logged, 32);
  const Eigen::VectorXd y_logged = LoggedRows(y, logged);
  CheckRecordStarts(record_starts, y.size());
  RequireVaryingSignal("target", y_logged, "there is nothing to model");
  if (options.uses_temperature()) {
    // Checked before the decomposition, which is the slow part.
    internal::RequireTemperatureFor(temperature_c, y.size());
    internal::RequireChannelsFor(options, temperature_c.cols());
    for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
      RequireVaryingSignal("temperature", temperature_c.col(c),
                           "a drift model on temperature needs a record whose temperature changes");
    }
  }
  DriftOptions o = options;
  o.features = ForTrainingRecord(o.features, y.size());
  if (IsBaseline(o.method)) {
    // A filter of y itself (baseline.h): one sub-model, no decomposition, no learner.
    DriftModel model;
    model.options = o;
    model.lags = o.mode == Mode::kPredict ? 1 : 0;
    model.training_samples = CountLogged(logged, y.size());
    // Carry: the logged rows only, as every fit (the made-up rows are not data).
    auto baseline = std::make_shared<const Baseline>(FitBaseline(o.method, y_logged));
    model.sub_models.push_back({.name = "signal", .has_residue = true, .baseline = std::move(baseline)});
    if (model.uses_temperature()) {
      model.temperature_min_c = temperature_c.col(0).minCoeff();
      model.temperature_max_c = temperature_c.col(0).maxCoeff();
    }
    execution.Report(1.0, "fit sub-models");
    return model;
  }
  internal::SubSeries prepared = internal::PrepareSubSeries(y, o, execution);
  const Eigen::MatrixXd thermal = internal::ThermalOrEmpty(prepared.model, temperature_c, y.size());
  const bool decomposed = UsesDecomposition(options.method);
  execution.Report(decomposed ? internal::kGroupsDoneShare : 0.0, "fit sub-models");
  internal::FitLearners(prepared.model, prepared.series, y, thermal, y.size(), temperature_c,
                        record_starts, execution.threads, logged);
  if (prepared.model.uses_temperature()) {
    prepared.model.temperature_min_c = temperature_c.col(0).minCoeff();
    prepared.model.temperature_max_c = temperature_c.col(0).maxCoeff();
  }
  execution.Report(1.0, "fit sub-models");
  // A model holds the options it was fitted with, as given: plain values, nothing of how the fit
  // ran (its threads and callbacks are the execution's, which a model never sees).
  assert(prepared.model.options == o);
  return std::move(prepared.model);
}

}  // namespace gyrodrift::drift
