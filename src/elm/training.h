// Private: the training steps of the ELM (elm::Fit; the hidden layer also serves Predict): hidden
// units, the streamed Gram matrix, ridge solvers and the leave-one-out grid. Everything that
// touches the N rows works on fixed row blocks of kBlockRows, so the floating-point operations do
// not depend on the number of threads.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "gyrodrift/elm/elm.h"

namespace gyrodrift::elm::internal {

// Rows per block. Large enough that the per-block products run at GEMM speed, small enough that
// the per-worker buffers (kBlockRows x L doubles) stay modest.
inline constexpr Eigen::Index kBlockRows = 4096;

inline int NumBlocks(Eigen::Index rows) {
  return static_cast<int>((rows + kBlockRows - 1) / kBlockRows);
}

// Draws L hidden units for d inputs: unit j uses Rng(seed, j), d weights U[-1,1] then the bias
// U[0,1], so the first L units do not depend on how many are drawn.
void DrawUnits(int inputs, int hidden, std::uint64_t seed, Eigen::MatrixXd* weights,
               Eigen::VectorXd* biases);

// out (rows x L) = g(xs A + b) for standardised inputs xs (rows x d); A is d x L, b has L
// entries (RBF: g = exp(-b ||x - a||^2 / d)). `out` may be a block of a larger buffer. Each
// entry is the same bits whatever the number of rows or the entry's position (elm_kernels.h).
void ComputeHidden(Activation activation, const Eigen::Ref<const Eigen::MatrixXd>& xs,
                   const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases,
                   Eigen::Ref<Eigen::MatrixXd> out);

// H^T H (lower triangle valid) and H^T T of the hidden layer of xs, streamed over row blocks.
struct Gram {
  Eigen::MatrixXd hth;  // L x L, lower triangle (the strict upper triangle is zero)
  Eigen::MatrixXd htt;  // L x m
};
Gram ComputeGram(Activation activation, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts,
                 const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases, int threads);

// beta = (G + I/C)^{-1} H^T T by LLT (LDLT if LLT breaks down) of the leading L x L block of
// the lower triangle of `hth`.
struct RidgeSolution {
  Eigen::MatrixXd beta;    // L x m
  double condition = 0.0;  // 1 / rcond of the factorisation
  bool ldlt_fallback = false;
};
RidgeSolution SolveRidgeCholesky(const Eigen::MatrixXd& hth, const Eigen::MatrixXd& htt, int hidden,
                                 double ridge_c);

// Leave-one-out (PRESS) errors over the (L, C) grid; see elm.h. Fills `candidates` L-major.
void LooGrid(Activation activation, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts,
             const Eigen::MatrixXd& weights, const Eigen::VectorXd& biases, const Gram& gram,
             const std::vector<int>& hidden_grid, const std::vector<double>& ridge_grid,
             double max_condition, const Eigen::RowVectorXd& target_scale, int threads,
             std::vector<LooCandidate>* candidates);

}  // namespace gyrodrift::elm::internal
