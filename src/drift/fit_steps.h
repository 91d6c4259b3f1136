// Private: the steps FitDriftModel is made of (drift_fit.cc), shared with the evaluation's paper
// protocol (which decomposes the whole record but fits on the training rows only), with
// DriftOptions::Validate (the learner kind) and with prediction (the thermal inputs).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift::internal {

// The learner kind of a method's sub-models: kPoly, kSvr and kBp their own, every other an ELM.
LearnerKind KindOf(Method method);

// Sub-model g's own random stream (common/random.h: the seed rule) and its learner's options.
std::uint64_t SubModelSeed(const DriftOptions& o, size_t g);
LearnerOptions SubModelLearner(const DriftOptions& o, size_t g);

// Rows of inputs of a predict-mode sub-model on series s (its model.lags lags, then the thermal
// features of the row before, if any) for t = first .. first + count - 1.
Eigen::MatrixXd PredictRows(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& s,
                            const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index first,
                            Eigen::Index count);

// Throws DataError unless temperature_c has n rows, at least one column, and finite values.
void RequireTemperatureFor(const Eigen::Ref<const Eigen::MatrixXd>& temperature_c, Eigen::Index n);

// Throws OptionError when `channels` temperature columns are given to the options' method, which
// takes one unless it identifies thermal models.
void RequireChannelsFor(const DriftOptions& o, Eigen::Index channels);

// The thermal features (N x F) a model's learners take from a temperature record (N x C), or an
// N x 0 matrix when it takes none (no temperature, or identified sub-models, which read the
// channels themselves). Checks the record as RequireTemperatureFor and RequireChannelsFor.
Eigen::MatrixXd ThermalOrEmpty(const DriftModel& model,
                               const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                               Eigen::Index n);

struct SubSeries {
  DriftModel model;        // options and sub-model definitions, no learners yet
  Eigen::MatrixXd series;  // N x G sub-series of the decomposed record
};

// Decomposes y (if the method needs it) on execution.threads, groups the IMFs and defines the
// sub-models. Reports "decompose" (fractions up to kDecomposeShare) through execution.progress.
constexpr double kDecomposeShare = 0.7;
constexpr double kGroupsDoneShare = 0.85;  // the decomposition and the grouping done
SubSeries PrepareSubSeries(const Eigen::Ref<const Eigen::VectorXd>& y, const DriftOptions& o,
                           const Execution& execution);

// The decomposing methods' own steps. Each decomposes y with dopt in the context and defines the
// model's sub-models (none when the decomposition has no IMF; PrepareSubSeries then models the
// signal whole).
// MS-ELM (ms_elm.cc): the PDF-similarity grouping (selection/pdf_similarity.cc) into noise,
// mixed and drift sub-models; sets model.selection_summary.
decomposition::Decomposition DecomposeForMsElm(const Eigen::Ref<const Eigen::VectorXd>& y,
                                               const decomposition::DecompositionOptions& dopt,
                                               const decomposition::DecompositionContext& context,
                                               DriftModel& model);
// EMD-ELM (emd_elm.cc): one sub-model per IMF and one for the residue.
decomposition::Decomposition DecomposeForEmdElm(const Eigen::Ref<const Eigen::VectorXd>& y,
                                                const decomposition::DecompositionOptions& dopt,
                                                const decomposition::DecompositionContext& context,
                                                DriftModel& model);

// MS-ELM, predict mode (ms_elm.cc): the noise group, white by the selection's test, is predicted
// by its training mean unless its learner, refitted on the first 1 - validation_fraction of the
// first fit_end rows, removes at least kWhiteGroupMinSkill of the held-out mean-square error of
// that part's mean (docs/drift.md 1.2). Called once the learners are fitted.
void PredictWhiteGroupByMean(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                             const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                             const Execution& learners);

// Fits every sub-model on rows t < fit_end of the series (and thermal features, N x F or empty;
// identified sub-models read the temperature channels, N x C, instead, as records: features.h).
// Learners run on `threads` workers (Execution::threads). `logged` (features.h; empty = every
// row, else fit_end flags) keeps the fit to the logged rows: compensate mode only.
void FitLearners(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                 const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                 const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                 const std::vector<Eigen::Index>& record_starts, int threads,
                 const std::vector<bool>& logged = {});

}  // namespace gyrodrift::drift::internal
