// MS-ELM's own steps (fit_steps.h): the decomposition grouped by the PDF-similarity criterion
// into noise, mixed and drift sub-models (METHOD.md sections 4-5; the criterion is
// selection/pdf_similarity.cc), and the white noise group predicted by its mean.
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "drift/fit_steps.h"
#include "gyrodrift/selection/selection.h"

namespace gyrodrift::drift::internal {

decomposition::Decomposition DecomposeForMsElm(const Eigen::Ref<const Eigen::VectorXd>& y,
                                               const decomposition::DecompositionOptions& dopt,
                                               const decomposition::DecompositionContext& context,
                                               DriftModel& model) {
  selection::SelectionOptions sopt = model.options.selection;
  // The white-noise level, when it cannot reuse the decomposition's noise, draws the same
  // realisations itself: the user's seed, not the Monte-Carlo's default.
  sopt.monte_carlo.seed = model.options.seed;
  selection::GroupedDecomposition grouped = selection::DecomposeAndSelect(y, dopt, sopt, context);
  if (grouped.selection) {
    model.selection_summary = grouped.selection->Summary();
    for (const auto& group : grouped.selection->groups) {
      model.sub_models.push_back(
          {std::string(selection::ToString(group.kind)), group.imfs, group.has_residue, nullptr});
    }
  }
  return std::move(grouped.decomposition);
}

// The share of the held-out mean-square error of the training mean that the noise group's
// learner must remove to be kept [choice, docs/drift.md 1.2]. The sum of white-noise IMFs 1..k_N
// is white noise less its slow modes: a learner on its lags predicts a few per cent of it (4.5 %
// of the training MSE on the chamber record), which is noise, not drift, and what it predicts is
// added to the sum, so against the drift it costs as much as it gains against the next sample.
// Drift content misjudged as noise would be predicted far better than that.
constexpr double kWhiteGroupMinSkill = 0.1;

void PredictWhiteGroupByMean(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                             const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                             const Execution& learners) {
  const DriftOptions& o = model.options;
  const int p = model.lags;
  const Eigen::Index validation =
      static_cast<Eigen::Index>(std::floor(o.validation_fraction * fit_end));
  const Eigen::Index inner_end = fit_end - validation;
  if (validation < 1 || inner_end - p < 8) return;  // too short to judge: the learner stays
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    SubModel& sub = model.sub_models[g];
    if (sub.name != selection::ToString(selection::GroupKind::kNoise)) continue;
    const auto s = series.col(static_cast<Eigen::Index>(g));
    const auto held_out = s.segment(inner_end, validation);
    const std::unique_ptr<Learner> inner =
        FitLearner(PredictRows(model, s, thermal, p, inner_end - p), s.segment(p, inner_end - p),
                   SubModelLearner(o, g), learners);
    const double learner_sse =
        (inner->Predict(PredictRows(model, s, thermal, inner_end, validation)) - held_out)
            .squaredNorm();
    const double mean_sse = (held_out.array() - s.head(inner_end).mean()).square().sum();
    if (learner_sse < (1.0 - kWhiteGroupMinSkill) * mean_sse) continue;
    sub.learner = nullptr;
    sub.mean = s.head(fit_end).mean();
  }
}

}  // namespace gyrodrift::drift::internal
