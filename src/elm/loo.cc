// Closed-form leave-one-out (PRESS) errors of ridge ELMs over a grid of (L, C).
//
// For candidate L, H_L = H[:, :L] (the units are nested) and H_L^T H_L = V diag(lambda) V^T is
// the leading block of the full Gram matrix. With P = H_L V and delta = 1/C:
//   fitted values     y_i   = sum_j P_ij z_j / (lambda_j + delta),  z = V^T H_L^T T
//   hat diagonal      h_ii  = sum_j P_ij^2 / (lambda_j + delta)
//   PRESS residual    e_i   = (t_i - y_i) / (1 - h_ii)
// so one eigendecomposition and one N x L x L product per candidate L serve every C.
// The rows are streamed in fixed blocks; each block returns its sums of e^2 and the sums are
// added in block order, so the result does not depend on the thread count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "elm/elm_kernels.h"
#include "elm/training.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::elm::internal {
namespace {

// Everything the row pass needs about one candidate L.
struct CandidatePlan {
  int hidden = 0;
  std::vector<int> active;        // indices into the C grid that are evaluated
  Eigen::MatrixXd vectors;        // V, L x L
  Eigen::MatrixXd hat_weights;    // L x |active|: 1 / (lambda_j + delta_c)
  Eigen::MatrixXd fit_weights;    // L x (|active| m): z_jk / (lambda_j + delta_c), c-major
  std::vector<double> condition;  // per C of the grid
};

}  // namespace

namespace {

// Candidate L's eigendecomposition of the leading L x L block of H^T H (the lower triangle
// ComputeGram fills) and its weights for every C whose condition is at most max_condition.
CandidatePlan PlanCandidate(const Kernels& kernels, const Gram& gram, int hidden,
                            const std::vector<double>& ridge_grid, double max_condition) {
  const int num_c = static_cast<int>(ridge_grid.size());
  const Eigen::Index outputs = gram.htt.cols();
  CandidatePlan plan;
  plan.hidden = hidden;
  const Eigen::Index l = plan.hidden;
  Eigen::VectorXd values(l);
  plan.vectors.resize(l, l);
  kernels.eigen(gram.hth.data(), gram.hth.outerStride(), l, values.data(), plan.vectors.data());
  // A failed decomposition (NaN eigenvalues) leaves the candidate with no evaluated C.
  const bool decomposed = values.allFinite();
  // H^T H is positive semi-definite; rounding can leave tiny negative eigenvalues.
  const Eigen::ArrayXd lambda = values.array().max(0.0);
  const Eigen::MatrixXd z = plan.vectors.transpose() * gram.htt.topRows(l);
  plan.condition.resize(static_cast<size_t>(num_c));
  for (int c = 0; c < num_c; ++c) {
    const double delta = 1.0 / ridge_grid[static_cast<size_t>(c)];
    plan.condition[static_cast<size_t>(c)] =
        decomposed ? (lambda.maxCoeff() + delta) / (lambda.minCoeff() + delta)
                   : std::numeric_limits<double>::quiet_NaN();
    if (plan.condition[static_cast<size_t>(c)] <= max_condition) plan.active.push_back(c);
  }
  const Eigen::Index num_active = static_cast<Eigen::Index>(plan.active.size());
  plan.hat_weights.resize(l, num_active);
  plan.fit_weights.resize(l, num_active * outputs);
  for (Eigen::Index a = 0; a < num_active; ++a) {
    const double delta = 1.0 / ridge_grid[static_cast<size_t>(plan.active[static_cast<size_t>(a)])];
    plan.hat_weights.col(a) = (lambda + delta).inverse().matrix();
    for (Eigen::Index k = 0; k < outputs; ++k) {
      plan.fit_weights.col(a * outputs + k) = z.col(k).cwiseProduct(plan.hat_weights.col(a));
    }
  }
  return plan;
}

// The summed squared PRESS residuals of every plan's evaluated (C, output), at offset[q] for
// plan q: the rows streamed in fixed blocks, the block sums added in block order.
Eigen::VectorXd PressSums(Activation activation, const Eigen::MatrixXd& xs,
                          const Eigen::MatrixXd& ts, const Eigen::MatrixXd& weights,
                          const Eigen::VectorXd& biases, const std::vector<CandidatePlan>& plans,
                          const std::vector<Eigen::Index>& offset, int threads) {
  const Eigen::Index n = xs.rows();
  const Eigen::Index outputs = ts.cols();
  const int num_l = static_cast<int>(plans.size());
  const Eigen::Index total = offset.back();
  Eigen::VectorXd sse = Eigen::VectorXd::Zero(total);
  if (total == 0) return sse;
  int max_hidden = 0;
  Eigen::Index max_active = 0;
  std::vector<LooPlanView> views(static_cast<size_t>(num_l));
  for (int q = 0; q < num_l; ++q) {
    const CandidatePlan& plan = plans[static_cast<size_t>(q)];
    max_hidden = std::max(max_hidden, plan.hidden);
    max_active = std::max(max_active, static_cast<Eigen::Index>(plan.active.size()));
    views[static_cast<size_t>(q)] = {plan.hidden,
                                     static_cast<long>(plan.active.size()),
                                     plan.vectors.data(),
                                     plan.fit_weights.data(),
                                     plan.hat_weights.data(),
                                     offset[static_cast<size_t>(q)]};
  }
  const int blocks = NumBlocks(n);
  const int workers = std::min(ResolveThreads(threads), blocks);
  const Eigen::Index block_rows = std::min(n, kBlockRows);
  struct Workspace {
    Eigen::MatrixXd h, p, fitted, hat;
  };
  std::vector<Workspace> work(static_cast<size_t>(workers));
  for (auto& w : work) {
    w.h.resize(block_rows, max_hidden);
    w.p.resize(block_rows, max_hidden);
    w.fitted.resize(block_rows, max_active * outputs);
    w.hat.resize(block_rows, max_active);
  }
  const Kernels& kernels = ActiveKernels();
  ParallelOrderedReduce(
      blocks, workers,
      [&](int block, int worker) {
        Workspace& w = work[static_cast<size_t>(worker)];
        const Eigen::Index r0 = block * kBlockRows;
        const Eigen::Index rows = std::min(kBlockRows, n - r0);
        auto h = w.h.topRows(rows);
        ComputeHidden(activation, xs.middleRows(r0, rows), weights, biases, h);
        Eigen::VectorXd sums = Eigen::VectorXd::Zero(total);
        kernels.loo(h.data(), h.outerStride(), rows, ts.data() + r0, ts.outerStride(), outputs,
                    views.data(), num_l, w.p.data(), w.fitted.data(), w.hat.data(), sums.data());
        return sums;
      },
      [&](int, Eigen::VectorXd&& sums) { sse += sums; });
  return sse;
}

}  // namespace

void LooGrid(Activation activation, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts,
             const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases, const Gram& gram,
             const std::vector<int>& hidden_grid, const std::vector<double>& ridge_grid,
             double max_condition, const Eigen::RowVectorXd& target_scale, int threads,
             std::vector<LooCandidate>* candidates) {
  const Eigen::Index n = xs.rows();
  const Eigen::Index outputs = ts.cols();
  const int num_l = static_cast<int>(hidden_grid.size());
  const int num_c = static_cast<int>(ridge_grid.size());
  const Kernels& kernels = ActiveKernels();

  // One eigendecomposition per candidate, spread over the workers (each is independent).
  std::vector<CandidatePlan> plans(static_cast<size_t>(num_l));
  ParallelFor(num_l, threads, [&](int q, int) {
    plans[static_cast<size_t>(q)] = PlanCandidate(kernels, gram, hidden_grid[static_cast<size_t>(q)],
                                                  ridge_grid, max_condition);
  });

  // Offsets of each candidate's sums in the per-block result vector.
  std::vector<Eigen::Index> offset(static_cast<size_t>(num_l) + 1, 0);
  for (int q = 0; q < num_l; ++q) {
    const Eigen::Index num_active =
        static_cast<Eigen::Index>(plans[static_cast<size_t>(q)].active.size());
    offset[static_cast<size_t>(q) + 1] = offset[static_cast<size_t>(q)] + num_active * outputs;
  }
  const Eigen::VectorXd sse =
      PressSums(activation, xs, ts, weights, biases, plans, offset, threads);

  candidates->clear();
  const double count = static_cast<double>(n) * static_cast<double>(outputs);
  for (int q = 0; q < num_l; ++q) {
    const CandidatePlan& plan = plans[static_cast<size_t>(q)];
    size_t next_active = 0;
    for (int c = 0; c < num_c; ++c) {
      LooCandidate cand;
      cand.hidden_units = plan.hidden;
      cand.ridge_c = ridge_grid[static_cast<size_t>(c)];
      cand.condition = plan.condition[static_cast<size_t>(c)];
      if (next_active < plan.active.size() && plan.active[next_active] == c) {
        const Eigen::Index base =
            offset[static_cast<size_t>(q)] + static_cast<Eigen::Index>(next_active) * outputs;
        double sum_std = 0.0, sum_units = 0.0;
        for (Eigen::Index k = 0; k < outputs; ++k) {
          sum_std += sse[base + k];
          sum_units += sse[base + k] * target_scale[k] * target_scale[k];
        }
        cand.loo_mse = sum_std / count;
        cand.loo_rmse = std::sqrt(sum_units / count);
        ++next_active;
      } else {
        cand.skipped = true;
      }
      candidates->push_back(cand);
    }
  }
}

}  // namespace gyrodrift::elm::internal
