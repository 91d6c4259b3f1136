// Hidden units, the streamed Gram matrix and the Cholesky ridge solver.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "elm/internal.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::elm::internal {

void DrawUnits(int inputs, int hidden, std::uint64_t seed, Eigen::MatrixXd* weights,
               Eigen::VectorXd* biases) {
  weights->resize(inputs, hidden);
  biases->resize(hidden);
  for (int j = 0; j < hidden; ++j) {
    Rng rng(seed, static_cast<std::uint64_t>(j));
    for (int i = 0; i < inputs; ++i) (*weights)(i, j) = rng.Uniform(-1.0, 1.0);
    (*biases)[j] = rng.Uniform();
  }
}

void ComputeHidden(Activation activation, const Eigen::Ref<const Eigen::MatrixXd>& xs,
                   const Eigen::Ref<const Eigen::MatrixXd>& weights,
                   const Eigen::Ref<const Eigen::VectorXd>& biases,
                   Eigen::Ref<Eigen::MatrixXd> out) {
  out.noalias() = xs * weights;
  auto z = out.array();
  switch (activation) {
    case Activation::kSigmoid:
      z.rowwise() += biases.transpose().array();
      // exp(-z) overflows to +inf for z < -709, and 1 / (1 + inf) = 0 is the right limit.
      z = (1.0 + (-z).exp()).inverse();
      break;
    case Activation::kTanh:
      z.rowwise() += biases.transpose().array();
      z = z.tanh();
      break;
    case Activation::kSine:
      z.rowwise() += biases.transpose().array();
      z = z.sin();
      break;
    case Activation::kLinear:
      z.rowwise() += biases.transpose().array();
      break;
    case Activation::kRbf: {
      // ||x - a||^2 = ||x||^2 - 2 x.a + ||a||^2; the inputs are standardised, so the
      // cancellation costs at most a few ulps of the row norm. Clamped at 0.
      const double inv_d = 1.0 / static_cast<double>(std::max<Eigen::Index>(xs.cols(), 1));
      const Eigen::ArrayXd row_norm2 = xs.rowwise().squaredNorm().array();
      for (Eigen::Index j = 0; j < out.cols(); ++j) {
        const double a_norm2 = weights.col(j).squaredNorm();
        const double gamma = biases[j] * inv_d;
        auto col = z.col(j);
        col = ((row_norm2 - 2.0 * col + a_norm2).max(0.0) * (-gamma)).exp();
      }
      break;
    }
  }
}

Gram ComputeGram(Activation activation, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts,
                 const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases, int threads) {
  const Eigen::Index n = xs.rows();
  const Eigen::Index hidden = weights.cols();
  const Eigen::Index outputs = ts.cols();
  const int blocks = NumBlocks(n);
  const int workers = std::min(ResolveThreads(threads), blocks);
  std::vector<Eigen::MatrixXd> h_buffer(static_cast<size_t>(workers),
                                        Eigen::MatrixXd(std::min(n, kBlockRows), hidden));
  Gram gram;
  gram.hth = Eigen::MatrixXd::Zero(hidden, hidden);
  gram.htt = Eigen::MatrixXd::Zero(hidden, outputs);
  struct Partial {
    Eigen::MatrixXd hth;
    Eigen::MatrixXd htt;
  };
  ParallelOrderedReduce(
      blocks, workers,
      [&](int block, int worker) {
        const Eigen::Index r0 = block * kBlockRows;
        const Eigen::Index rows = std::min(kBlockRows, n - r0);
        auto h = h_buffer[static_cast<size_t>(worker)].topRows(rows);
        ComputeHidden(activation, xs.middleRows(r0, rows), weights, biases, h);
        Partial p;
        p.hth = Eigen::MatrixXd::Zero(hidden, hidden);
        p.hth.selfadjointView<Eigen::Lower>().rankUpdate(h.transpose());
        p.htt.noalias() = h.transpose() * ts.middleRows(r0, rows);
        return p;
      },
      [&](int block, Partial&& p) {
        if (block == 0) {
          gram.hth = std::move(p.hth);
          gram.htt = std::move(p.htt);
        } else {
          gram.hth.triangularView<Eigen::Lower>() += p.hth;
          gram.htt += p.htt;
        }
      });
  return gram;
}

RidgeSolution SolveRidgeCholesky(const Eigen::MatrixXd& hth, const Eigen::MatrixXd& htt, int hidden,
                                 double ridge_c) {
  Eigen::MatrixXd system = hth.topLeftCorner(hidden, hidden);
  system.diagonal().array() += 1.0 / ridge_c;
  RidgeSolution solution;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(system);
  if (llt.info() == Eigen::Success) {
    solution.beta = llt.solve(htt.topRows(hidden));
    solution.condition = 1.0 / llt.rcond();
    return solution;
  }
  // Only when 1/C is below the rounding level of H^T H: LDLT with pivoting still gives the
  // ridge solution of the rounded system.
  Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower> ldlt(system);
  solution.beta = ldlt.solve(htt.topRows(hidden));
  solution.condition = 1.0 / ldlt.rcond();
  solution.ldlt_fallback = true;
  return solution;
}

}  // namespace gyrodrift::elm::internal
