// Hidden units, the streamed Gram matrix and the Cholesky ridge solver. The arithmetic over
// rows runs in the dispatched kernels (kernels.h).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "elm/internal.h"
#include "elm/kernels.h"
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
  const int blocks = NumBlocks(n);
  const int workers = std::min(ResolveThreads(threads), blocks);
  const Kernels& kernels = ActiveKernels();
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
        // The strict upper triangle of p.hth is never read: left uninitialised.
        Partial p{Eigen::MatrixXd(hidden, hidden), Eigen::MatrixXd(hidden, outputs)};
        kernels.gram(h.data(), h.outerStride(), rows, hidden, ts.data() + r0, ts.outerStride(),
                     outputs, p.hth.data(), p.htt.data());
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
  // Only the lower triangle is summed; a defined upper triangle keeps any later reader honest.
  gram.hth.triangularView<Eigen::StrictlyUpper>().setZero();
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
