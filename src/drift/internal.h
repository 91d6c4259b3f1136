// Private: the steps FitDriftModel is made of, shared with the evaluation's paper protocol (which
// decomposes the whole record but fits on the training rows only).
#pragma once

#include <Eigen/Core>

#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift::internal {

struct SubSeries {
  DriftModel model;        // options and sub-model definitions, no learners yet
  Eigen::MatrixXd series;  // N x G sub-series of the decomposed record
};

// Decomposes y (if the method needs it), groups the IMFs and defines the sub-models.
// Reports "decompose" (fractions up to kDecomposeShare) through o.progress when `report` is set.
constexpr double kDecomposeShare = 0.7;
constexpr double kGroupsDoneShare = 0.85;  // the decomposition and the grouping done
SubSeries PrepareSubSeries(const Eigen::Ref<const Eigen::VectorXd>& y, const DriftOptions& o,
                           bool report = false);

// Throws OptionError naming `horizon` unless it is in [1, kMaxHorizon].
void RequireHorizon(int horizon);

// The one history rule of prediction: the first sample (0-based) predictable `horizon` steps
// ahead with `lags` lags, its origin first - horizon + 1 needing the lags before it and, when
// `windowed` (the causal protocol's decompositions), the shortest causal window (16 samples).
Eigen::Index FirstPredictable(int lags, bool windowed, int horizon);

// Throws OptionError when `channels` temperature columns are given to the options' method, which
// takes one unless it identifies thermal models.
void RequireChannelsFor(const DriftOptions& o, Eigen::Index channels);

// Fits every sub-model on rows t < fit_end of the series (and thermal features, N x F or empty;
// identified sub-models read the temperature channels, N x C, instead, as records: features.h).
void FitLearners(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                 const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                 const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                 const std::vector<Eigen::Index>& record_starts = {});

}  // namespace gyrodrift::drift::internal
