// Private: per-thread density buffers, shared by the selection sources (SelectModes, the
// white-noise level), and the self-similarity G_k computed in them.
#pragma once

#include <Eigen/Core>

#include "gyrodrift/selection/distance.h"
#include "gyrodrift/selection/kde.h"

namespace gyrodrift::selection::internal {

// Per-thread buffers: repeated calls of the same size allocate nothing.
struct Scratch {
  KdeWorkspace kde;
  Eigen::VectorXd density;    // standardised-grid density (SelfSimilarity)
  Eigen::VectorXd reference;  // N(0, 1 + h^2) on that grid
  Eigen::VectorXd common;     // density on the common grid of x and the IMFs
};

// SelfSimilarityDistance with caller-owned buffers.
double SelfSimilarity(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& kde,
                      PdfDistance distance, Scratch* scratch);

}  // namespace gyrodrift::selection::internal
