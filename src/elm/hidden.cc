// Hidden units, the streamed Gram matrix and the Cholesky ridge solver. The arithmetic over
// rows runs in the dispatched kernels (elm_kernels.h).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "elm/elm_kernels.h"
#include "elm/training.h"
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

static_assert(static_cast<int>(Activation::kSigmoid) == kKernelSigmoid &&
              static_cast<int>(Activation::kTanh) == kKernelTanh &&
              static_cast<int>(Activation::kSine) == kKernelSine &&
              static_cast<int>(Activation::kRbf) == kKernelRbf &&
              static_cast<int>(Activation::kLinear) == kKernelLinear);

void ComputeHidden(Activation activation, const Eigen::Ref<const Eigen::MatrixXd>& xs,
                   const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases,
                   Eigen::Ref<Eigen::MatrixXd> out) {
  ActiveKernels().hidden(static_cast<int>(activation), xs.data(), xs.outerStride(), xs.rows(),
                         xs.cols(), weights.data(), biases.data(), weights.cols(), out.data(),
                         out.outerStride());
}

Gram ComputeGram(Activation activation, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts,
                 const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases, int threads) {
  const Eigen::Index n = xs.rows();
  const Eigen::Index hidden = weights.cols();
  const Eigen::Index outputs = ts.cols();
  const Eigen::Index cols = hidden + outputs;
  const int blocks = NumBlocks(n);
  const int workers = std::min(ResolveThreads(threads), blocks);
  const Kernels& kernels = ActiveKernels();
  // Each worker's block is [H T]: one symmetric rank update then gives H^T H and, in its last
  // rows, T^T H, at matrix-product speed (a separate H^T T would stream H again).
  std::vector<Eigen::MatrixXd> buffer(static_cast<size_t>(workers),
                                      Eigen::MatrixXd(std::min(n, kBlockRows), cols));
  Eigen::MatrixXd sum;  // cols x cols, lower triangle
  ParallelOrderedReduce(
      blocks, workers,
      [&](int block, int worker) {
        const Eigen::Index r0 = block * kBlockRows;
        const Eigen::Index rows = std::min(kBlockRows, n - r0);
        auto ht = buffer[static_cast<size_t>(worker)].topRows(rows);
        ComputeHidden(activation, xs.middleRows(r0, rows), weights, biases, ht.leftCols(hidden));
        ht.rightCols(outputs) = ts.middleRows(r0, rows);
        // The strict upper triangle is never read: left uninitialised.
        Eigen::MatrixXd partial(cols, cols);
        kernels.gram(ht.data(), ht.outerStride(), rows, cols, partial.data());
        return partial;
      },
      [&](int block, Eigen::MatrixXd&& partial) {
        if (block == 0) {
          sum = std::move(partial);
        } else {
          sum.triangularView<Eigen::Lower>() += partial;
        }
      });
  Gram gram;
  gram.hth = sum.topLeftCorner(hidden, hidden);
  // Only the lower triangle was summed; a defined upper triangle keeps any later reader honest.
  gram.hth.triangularView<Eigen::StrictlyUpper>().setZero();
  gram.htt = sum.bottomLeftCorner(outputs, hidden).transpose();
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
