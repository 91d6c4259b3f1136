// Extreme learning machine: a single-hidden-layer network with random hidden weights and
// ridge-regularised least-squares output weights, with closed-form leave-one-out selection of
// the number of hidden units L and the ridge parameter C.
//
// Model (Huang, Zhu & Siew, Neurocomputing 70, 2006; ridge form: Huang, Zhou, Ding & Zhang,
// IEEE TSMC-B 42, 2012):
//   x_s = (x - x_mean) / x_scale,   H_ij = g(x_s,i . a_j + b_j),   y = H beta * t_scale + t_mean
//   beta = argmin ||H beta - T_s||^2 + ||beta||^2 / C = (H^T H + I/C)^{-1} H^T T_s
// a_j ~ U[-1,1]^d, b_j ~ U[0,1]; hidden unit j draws from Rng(seed, j), so the first L units of
// a network with L' > L units are exactly the units of the network with L units.
// The Gaussian RBF unit is g = exp(-b_j ||x_s - a_j||^2 / d), centre a_j ~ U[-1,1]^d in the
// standardised input space and impact factor b_j ~ U[0,1] (Huang et al. 2006 draw the RBF
// centre and impact factor at random; the 1/d keeps the exponent of order one for any d).
// Solvers: Cholesky (LLT, LDLT fallback) of H^T H + I/C, or Householder QR of [H; I/sqrt(C)];
// C = infinity is the minimum-norm least-squares solution by a complete orthogonal
// decomposition of H. Never an explicit inverse.
// Leave-one-out (PRESS, Allen 1974; as in hpelm, Akusok et al., IEEE Access 3, 2015): for ridge
// regression with hat matrix P = H (H^T H + I/C)^{-1} H^T, e_loo,i = (t_i - y_i) / (1 - P_ii).
// With H^T H = V diag(lambda) V^T, P_ii = sum_j (H V)_ij^2 / (lambda_j + 1/C): one
// eigendecomposition per candidate L gives every C of the grid.
//
// Units: outputs have the units of T; inputs any units (standardised internally).
// Cost (N rows, d inputs, m outputs, L units): fit O(N d L + N L^2 + L^3) with the Cholesky
// solver, O(N L^2) memory-free streaming over row blocks (H is never stored); QR stores H and
// costs 2 N L^2. Leave-one-out selection over candidates L_k <= L_max: O(N L_max^2) for H^T H
// plus O(N L_k^2 + L_k^3) per candidate. Row blocks run on the execution's (or Predict's) threads;
// results are the same bits for any thread count (blocks are fixed by N alone and sums run in
// block order), so a fitted model does not depend on how many threads fitted it.
// Instruction set: the row kernels are built for baseline x86-64 and for AVX2 + FMA and chosen
// at run time by the CPU. The FMA kernels round differently, so fitted weights, predictions and
// leave-one-out errors can differ in the last bits (about 1e-13 relative) between a CPU with
// AVX2 and one without; on one machine every result is reproducible to the bit, and a model
// read back from a file predicts exactly what it predicted before it was saved.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"

namespace gyrodrift::elm {

enum class Activation {
  kSigmoid,  // 1 / (1 + exp(-z))
  kTanh,     // tanh(z)
  kSine,     // sin(z)
  kRbf,      // exp(-b ||x - a||^2 / d), Gaussian
  kLinear,   // z (a random linear projection; with L >= d the model is linear regression)
};
std::string_view ToString(Activation activation);
Activation ActivationFromString(std::string_view name);  // "sigmoid", "tanh", "sine", "rbf",
                                                         // "linear"; throws UsageError

enum class Solver {
  kCholesky,  // LLT of H^T H + I/C (LDLT if LLT breaks down); streams H, the fast path
  kQr,        // Householder QR of [H; I/sqrt(C)]; C = inf: complete orthogonal decomposition
};
std::string_view ToString(Solver solver);
Solver SolverFromString(std::string_view name);  // "cholesky", "qr"; throws UsageError

enum class Selection {
  kFixed,  // L = hidden_units, C = ridge_c
  kAuto,   // L and C minimise the closed-form leave-one-out (PRESS) error over the grids
};
std::string_view ToString(Selection selection);
Selection SelectionFromString(std::string_view name);  // "fixed", "auto"; throws UsageError

// The most hidden units an ELM takes: its Gram matrix holds 8 L^2 bytes, 800 MB here (100000,
// the bound until 2026-11-28, asked for 80 GB and ended in "out of memory").
inline constexpr int kMaxHiddenUnits = 10000;

struct ElmOptions {
  // Number of hidden units L, in [1, kMaxHiddenUnits]. With selection = kAuto: the largest
  // candidate.
  // 20 per MS-ELM sub-model is the paper's default.
  int hidden_units = 20;
  Activation activation = Activation::kSigmoid;
  // Ridge parameter C (dimensionless, applies to the standardised problem), > 0; +infinity
  // means no regularisation and needs solver = kQr. Ignored by kAuto (see ridge_c_candidates).
  double ridge_c = 1e6;
  Solver solver = Solver::kCholesky;
  Selection selection = Selection::kFixed;
  // kAuto grids. Empty hidden_unit_candidates: the 1-2-5 series 1, 2, 5, 10, 20, 50, ... below
  // hidden_units, plus hidden_units itself. Empty ridge_c_candidates: 10^-2, 10^-1, ..., 10^10.
  // Every entry: hidden units in [1, hidden_units]; C finite and > 0.
  std::vector<int> hidden_unit_candidates{};
  std::vector<double> ridge_c_candidates{};
  // kAuto skips (L, C) pairs whose ridge system cond(H^T H + I/C) exceeds this (their
  // leave-one-out error is not computable to useful accuracy), in [1e3, 1e15].
  double max_condition = 1e12;
  // Standardise each input / target column to zero mean and unit standard deviation (population
  // std, fitted on the training rows only; a constant column is only centred).
  bool standardize_inputs = true;
  bool standardize_targets = true;
  std::uint64_t seed = 1;  // hidden unit j draws from Rng(seed, j)

  void Validate() const;  // throws UsageError "<field> = <value>: must be <rule>"
  bool operator==(const ElmOptions&) const = default;
  // The hidden-unit and C grids kAuto searches (the defaults above if the fields are empty).
  std::vector<int> HiddenUnitGrid() const;
  std::vector<double> RidgeGrid() const;
};

// Column-wise affine map x_s = (x - mean) / scale, fitted on training data.
struct Standardizer {
  Eigen::RowVectorXd mean;   // one entry per column
  Eigen::RowVectorXd scale;  // > 0; 1 for a constant column or when standardising is off
  Eigen::MatrixXd Apply(const Eigen::Ref<const Eigen::MatrixXd>& x) const;
  Eigen::MatrixXd Invert(const Eigen::Ref<const Eigen::MatrixXd>& x_s) const;
};
// Fits a Standardizer on `x`; with enabled = false returns mean 0, scale 1.
Standardizer FitStandardizer(const Eigen::Ref<const Eigen::MatrixXd>& x, bool enabled);

// Everything needed to predict and to serialise a fitted network. A plain struct: a model file
// reader fills the fields and calls Validate().
struct ElmModel {
  Activation activation = Activation::kSigmoid;
  Eigen::MatrixXd input_weights;   // d x L: column j is a_j (RBF: the centre)
  Eigen::VectorXd biases;          // L: b_j (RBF: the impact factor)
  Eigen::MatrixXd output_weights;  // L x m: beta, in standardised target units
  Standardizer input_scaler;       // d columns
  Standardizer target_scaler;      // m columns
  // As fitted: hidden_units = L, ridge_c = C actually used.
  ElmOptions options;

  int num_inputs() const { return static_cast<int>(input_weights.rows()); }
  int num_hidden() const { return static_cast<int>(input_weights.cols()); }
  int num_outputs() const { return static_cast<int>(output_weights.cols()); }
  // Throws DataError if the shapes disagree or a value is not finite (or a scale is <= 0).
  void Validate() const;
};

// Leave-one-out error of one (L, C) pair of the kAuto grid.
struct LooCandidate {
  int hidden_units = 0;
  double ridge_c = 0.0;
  double condition = 0.0;  // cond_2(H^T H + I/C) from the eigenvalues
  bool skipped = false;    // condition > max_condition: not evaluated, not selectable
  // PRESS mean squared error over rows and outputs in the standardised target space (the
  // selection criterion), and the LOO RMSE in target units (pooled over outputs).
  double loo_mse = std::numeric_limits<double>::quiet_NaN();
  double loo_rmse = std::numeric_limits<double>::quiet_NaN();
};

struct ElmReport {
  Selection selection = Selection::kFixed;
  Solver solver = Solver::kCholesky;
  int hidden_units = 0;  // L of the model
  double ridge_c = 0.0;  // C of the model
  int rows = 0;          // training rows N
  // Condition number estimate of the factorised system: Cholesky: 1-norm estimate of
  // cond(H^T H + I/C) (Eigen's LLT/LDLT rcond); QR: max|R_kk| / min|R_kk|, a lower bound of
  // cond_2 of [H; I/sqrt(C)] (or of H restricted to its numerical rank when C = inf).
  double condition_estimate = 0.0;
  bool ldlt_fallback = false;  // LLT found the system not positive definite; LDLT solved it
  int numerical_rank = 0;      // QR with C = inf: rank of H; otherwise L
  // Training RMSE in target units, pooled over outputs. Cholesky: from the normal equations
  // (sum t^2 - 2 beta^T H^T t + beta^T H^T H beta), accurate to about 1e-16 ||T_s||^2 / N in
  // squared standardised units; QR: from the residual.
  double train_rmse = 0.0;
  std::vector<LooCandidate> candidates;  // kAuto: every (L, C) pair, L-major, C ascending
  double loo_rmse = std::numeric_limits<double>::quiet_NaN();  // kAuto: of the chosen pair
  std::uint64_t seed = 0;
  int threads = 0;              // workers actually used
  std::string Summary() const;  // one line
};

struct ElmFit {
  ElmModel model;
  ElmReport report;
};

// Fits an ELM to inputs X (N x d) and targets T (N x m) on execution.threads workers (its progress
// is not called). Throws UsageError for bad options or threads and DataError for mismatched rows,
// fewer than 2 rows, no columns, or a non-finite value.
ElmFit Fit(const Eigen::Ref<const Eigen::MatrixXd>& x, const Eigen::Ref<const Eigen::MatrixXd>& t,
           const ElmOptions& options, const Execution& execution = {});

// Predictions in target units, N x m, on `threads` workers (0 = every core, in [0, 1024]; the
// result is the same bits for any count). Each row's prediction is the same bits whether it is
// predicted alone or within any batch. Throws DataError if X has the wrong column count or a
// non-finite value (the model is checked with Validate()), UsageError for a bad thread count.
Eigen::MatrixXd Predict(const ElmModel& model, const Eigen::Ref<const Eigen::MatrixXd>& x,
                        int threads = 0);

// Hidden-layer outputs H (N x L) of X in raw input units (the input scaler is applied), the
// same bits Fit used (on this CPU).
Eigen::MatrixXd HiddenLayer(const ElmModel& model, const Eigen::Ref<const Eigen::MatrixXd>& x,
                            int threads = 0);

// The row kernels this process runs: "avx2+fma" or "baseline" (decided once, by the CPU). The
// last bits of every result depend on it (see the header comment); worth recording next to
// results that are compared to the bit.
std::string_view KernelName();

}  // namespace gyrodrift::elm
