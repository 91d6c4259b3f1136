// Predict mode at run time: the history rule (FirstPredictable), the recursive H-step prediction
// from the sub-series' lags (PredictFromSeries, PredictRecursively) and PredictAhead, which gets
// those lags under either protocol: the paper's (one decomposition of the whole record) or the
// causal one (causal_protocol.cc).
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "drift/fit_steps.h"
#include "drift/prediction_steps.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

namespace internal {

void RequireHorizon(int horizon) {
  if (horizon < 1 || horizon > kMaxHorizon) {
    ThrowOption("horizon", std::to_string(horizon),
                "an integer in [1, " + std::to_string(kMaxHorizon) + "]");
  }
}

Eigen::Index FirstPredictable(int lags, bool windowed, int horizon) {
  RequireHorizon(horizon);
  constexpr Eigen::Index kShortestWindow = 16;
  const Eigen::Index min_origin = windowed ? std::max<Eigen::Index>(lags, kShortestWindow) : lags;
  return min_origin + horizon - 1;
}

}  // namespace internal

Eigen::Index FirstPredictable(const DriftModel& model, Protocol protocol, int horizon) {
  return internal::FirstPredictable(
      model.lags, protocol == Protocol::kCausal && UsesDecomposition(model.options.method),
      horizon);
}

namespace {

// Recursive prediction from each row's lags at its origin (lags[g](r, k) = s_g[origin + r - 1 -
// k]): step j predicts s_g[origin + r + j] from the lags (the predictions of the steps before
// standing in for the samples after the origin) and the thermal inputs at origin + r + j - 1, read
// from the record. The last step, summed over the groups, is the prediction of y[origin + r +
// horizon - 1].
Eigen::VectorXd PredictRecursively(const DriftModel& model,
                                   const std::vector<Eigen::MatrixXd>& lags,
                                   const Eigen::Ref<const Eigen::MatrixXd>& thermal,
                                   Eigen::Index origin, int horizon) {
  const int p = model.lags;
  const Eigen::Index count = lags.front().rows();
  Eigen::VectorXd prediction = Eigen::VectorXd::Zero(count);
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    if (model.sub_models[g].mean) {  // a constant at every step
      prediction.array() += *model.sub_models[g].mean;
      continue;
    }
    Eigen::MatrixXd x(count, p + thermal.cols());
    x.leftCols(p) = lags[g];
    for (int j = 0; j < horizon; ++j) {
      if (thermal.cols() > 0) {
        x.rightCols(thermal.cols()) = thermal.middleRows(origin + j - 1, count);
      }
      Eigen::VectorXd step = model.sub_models[g].learner->Predict(x);
      if (j + 1 == horizon) {
        prediction += step;
        break;
      }
      for (int k = p - 1; k > 0; --k) x.col(k) = x.col(k - 1);
      x.col(0) = std::move(step);
    }
  }
  return prediction;
}

}  // namespace

Eigen::VectorXd PredictFromSeries(const DriftModel& model,
                                  const Eigen::Ref<const Eigen::MatrixXd>& series,
                                  const Eigen::Ref<const Eigen::MatrixXd>& thermal,
                                  Eigen::Index first, Eigen::Index count, int horizon) {
  const Eigen::Index needed = internal::FirstPredictable(model.lags, false, horizon);
  if (first < needed) {
    throw DataError("prediction of sample " + std::to_string(first + 1) + " " +
                    std::to_string(horizon) + " steps ahead needs " + std::to_string(needed) +
                    " samples before it");
  }
  if (const auto& baseline = model.sub_models.front().baseline) {
    return ForecastBaseline(*baseline, series.col(0), first, count, horizon);
  }
  const Eigen::Index origin = first - (horizon - 1);
  std::vector<Eigen::MatrixXd> lags(model.sub_models.size());
  for (size_t g = 0; g < lags.size(); ++g) {
    lags[g] = LagRows(series.col(static_cast<Eigen::Index>(g)), model.lags, origin, count);
  }
  return PredictRecursively(model, lags, thermal, origin, horizon);
}

Eigen::VectorXd PredictAhead(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                             const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                             Eigen::Index first, int horizon, Protocol protocol,
                             const CausalOptions& causal, const Execution& execution) {
  if (model.options.mode != Mode::kPredict) {
    throw UsageError(
        "model mode = compensate: prediction needs a model fitted in mode predict");
  }
  RequireFiniteSignal("target", y, 2);
  const Eigen::Index n = y.size();
  causal.Validate();
  execution.Validate();
  const Eigen::Index min_first = FirstPredictable(model, protocol, horizon);
  if (first < min_first || first >= n) {
    throw DataError(
        "first predicted sample " + std::to_string(first + 1) + " must be in [" +
        std::to_string(min_first + 1) + ", " + std::to_string(n) +
        "] (the model needs that much history" +
        (horizon > 1 ? " before its " + std::to_string(horizon) + "-step horizon" : "") + ")");
  }
  const Eigen::MatrixXd thermal = internal::ThermalOrEmpty(model, temperature_c, n);
  const Eigen::Index count = n - first;
  const Eigen::Index origin = first - (horizon - 1);  // origin of the prediction of y[first]
  if (!UsesDecomposition(model.options.method)) {
    return PredictFromSeries(model, y, thermal, first, count, horizon);
  }
  if (protocol == Protocol::kPaper) {
    // The paper protocol reports no progress (it never did): only its threads are passed on.
    decomposition::DecompositionContext context;
    context.execution.threads = execution.threads;
    const Eigen::MatrixXd series =
        GroupSeries(model, decomposition::Decompose(y, internal::DecompositionFor(model), context));
    return PredictFromSeries(model, series, thermal, first, count, horizon);
  }
  return PredictRecursively(model, internal::CausalLags(model, y, origin, count, causal, execution),
                            thermal, origin, horizon);
}

Eigen::VectorXd PredictOneStep(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                               const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                               Eigen::Index first, Protocol protocol, const CausalOptions& causal,
                               const Execution& execution) {
  return PredictAhead(model, y, temperature_c, first, 1, protocol, causal, execution);
}

}  // namespace gyrodrift::drift
