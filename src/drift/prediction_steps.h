// Private: the parts of predict mode shared between prediction.cc, causal_protocol.cc and the
// evaluation: the history rule (how much record a prediction needs) and the causal protocol's
// lags (each origin's sub-series from its trailing windows alone, each with its mirrored tail).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift::internal {

// Throws OptionError naming `horizon` unless it is in [1, kMaxHorizon].
void RequireHorizon(int horizon);

// The one history rule of prediction: the first sample (0-based) predictable `horizon` steps
// ahead with `lags` lags, its origin first - horizon + 1 needing the lags before it and, when
// `windowed` (the causal protocol's decompositions), the shortest causal window (16 samples).
Eigen::Index FirstPredictable(int lags, bool windowed, int horizon);

// The decomposition a fitted model applies to new data: its options with its seed.
decomposition::DecompositionOptions DecompositionFor(const DriftModel& model);

// Causal protocol: the lags of each origin o = origin + r, r < count, from decomposing each
// trailing window y[o-L .. o-1] alone, L the distinct lengths min(L_w, o) of
// causal.WindowLengths(), followed by its mirrored tail y[o-2], y[o-3], ...
// (causal.DecomposedLength(L) - L samples): lags[g](r, k) = the mean over those windows of
// s_g[o - 1 - k] of their groups (count x lags per sub-model g). Origins run in parallel on
// execution.threads, which reports the fraction of origins done ("causal windows").
std::vector<Eigen::MatrixXd> CausalLags(const DriftModel& model,
                                        const Eigen::Ref<const Eigen::VectorXd>& y,
                                        Eigen::Index origin, Eigen::Index count,
                                        const CausalOptions& causal, const Execution& execution);

}  // namespace gyrodrift::drift::internal
