// Closed-form leave-one-out (src/elm/loo.cc): the PRESS error of every (L, C) pair equals
// brute-force refits that leave each row out, in the standardised criterion and in target units;
// the reported condition numbers are those of the eigenvalues; pairs above max_condition are
// skipped without shifting the others' sums; many row blocks and any thread count give the
// dense closed form and the same bits; and elm::Fit's auto selection picks the pair whose
// brute-force leave-one-out error is smallest, ties going to the smaller network and then the
// stronger regularisation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "elm/training.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::elm::internal {
namespace {

struct Problem {
  Eigen::MatrixXd xs, ts;  // already standardised-sized values
  Eigen::MatrixXd weights;
  Eigen::VectorXd biases;
  Eigen::MatrixXd h;  // N x L_max
};

// Smooth targets plus noise on random inputs; L_max sigmoid units of seed 3.
Problem MakeProblem(int n, int inputs, int outputs, int max_hidden, std::uint64_t seed,
                    double noise_sd = 0.1) {
  Rng rng(seed, 0);
  Problem p;
  p.xs.resize(n, inputs);
  p.ts.resize(n, outputs);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < inputs; ++j) p.xs(i, j) = rng.Uniform(-1.7, 1.7);
    for (int k = 0; k < outputs; ++k) {
      p.ts(i, k) = std::sin((k + 1) * p.xs(i, 0)) + 0.5 * p.xs.row(i).sum() - 0.2 * k +
                   noise_sd * rng.Normal();
    }
  }
  DrawUnits(inputs, max_hidden, 3, &p.weights, &p.biases);
  p.h.resize(n, max_hidden);
  ComputeHidden(Activation::kSigmoid, p.xs, p.weights, p.biases, p.h);
  return p;
}

std::vector<LooCandidate> RunLoo(const Problem& p, const std::vector<int>& hidden_grid,
                                 const std::vector<double>& ridge_grid, double max_condition,
                                 const Eigen::RowVectorXd& target_scale, int threads) {
  const Gram gram = ComputeGram(Activation::kSigmoid, p.xs, p.ts, p.weights, p.biases, threads);
  std::vector<LooCandidate> candidates;
  LooGrid(Activation::kSigmoid, p.xs, p.ts, p.weights, p.biases, gram, hidden_grid, ridge_grid,
          max_condition, target_scale, threads, &candidates);
  return candidates;
}

// Sum over rows of the squared leave-one-out residual per output: refit the ridge ELM on the
// other N - 1 rows (QR of [H; I/sqrt(C)], a different algorithm from the eigendecomposition)
// and predict the row left out.
Eigen::RowVectorXd BruteForceSse(const Eigen::MatrixXd& h_all, const Eigen::MatrixXd& t, int l,
                                 double c) {
  const Eigen::Index n = h_all.rows();
  const Eigen::MatrixXd h = h_all.leftCols(l);
  Eigen::RowVectorXd sse = Eigen::RowVectorXd::Zero(t.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n - 1 + l, l);
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n - 1 + l, t.cols());
    a.topRows(i) = h.topRows(i);
    a.middleRows(i, n - 1 - i) = h.bottomRows(n - 1 - i);
    a.bottomRows(l).diagonal().setConstant(1.0 / std::sqrt(c));
    b.topRows(i) = t.topRows(i);
    b.middleRows(i, n - 1 - i) = t.bottomRows(n - 1 - i);
    const Eigen::MatrixXd beta = a.colPivHouseholderQr().solve(b);
    sse += (h.row(i) * beta - t.row(i)).array().square().matrix();
  }
  return sse;
}

// cond_2(H_L^T H_L + I/C) from an independent eigensolver.
double Condition(const Eigen::MatrixXd& h_all, int l, double c) {
  const Eigen::MatrixXd g = h_all.leftCols(l).transpose() * h_all.leftCols(l);
  const Eigen::VectorXd lambda =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(g, Eigen::EigenvaluesOnly).eigenvalues();
  return (lambda.maxCoeff() + 1.0 / c) / (std::max(lambda.minCoeff(), 0.0) + 1.0 / c);
}

// Checks one evaluated candidate against brute force: loo_mse in the standardised space
// (averaged over rows and outputs) and loo_rmse with each output's scale.
void ExpectMatchesBruteForce(const LooCandidate& cand, const Problem& p,
                             const Eigen::RowVectorXd& scale) {
  const Eigen::RowVectorXd sse = BruteForceSse(p.h, p.ts, cand.hidden_units, cand.ridge_c);
  const double count = static_cast<double>(p.ts.size());
  const double mse = sse.sum() / count;
  const double rmse = std::sqrt((sse.array() * scale.array().square()).sum() / count);
  EXPECT_NEAR(cand.loo_mse, mse, 1e-10 * mse) << "L=" << cand.hidden_units << " C=" << cand.ridge_c;
  EXPECT_NEAR(cand.loo_rmse, rmse, 1e-10 * rmse)
      << "L=" << cand.hidden_units << " C=" << cand.ridge_c;
}

TEST(Loo, PressEqualsBruteForceRefitsForEveryPair) {
  const Problem p = MakeProblem(30, 2, 2, 20, 1);
  const std::vector<int> hidden_grid{1, 4, 10, 20};
  const std::vector<double> ridge_grid{0.01, 1.0, 100.0};
  const Eigen::RowVectorXd scale = (Eigen::RowVectorXd(2) << 2.0, 0.25).finished();
  const std::vector<LooCandidate> candidates = RunLoo(p, hidden_grid, ridge_grid, 1e15, scale, 1);
  ASSERT_EQ(candidates.size(), 12u);
  for (size_t q = 0; q < hidden_grid.size(); ++q) {
    for (size_t c = 0; c < ridge_grid.size(); ++c) {
      const LooCandidate& cand = candidates[q * ridge_grid.size() + c];
      // L-major, C ascending.
      ASSERT_EQ(cand.hidden_units, hidden_grid[q]);
      ASSERT_EQ(cand.ridge_c, ridge_grid[c]);
      ASSERT_FALSE(cand.skipped);
      ExpectMatchesBruteForce(cand, p, scale);
      const double cond = Condition(p.h, cand.hidden_units, cand.ridge_c);
      EXPECT_NEAR(cand.condition, cond, 1e-8 * cond);
    }
  }
  // A one-unit system has one eigenvalue: condition 1.
  EXPECT_NEAR(candidates[0].condition, 1.0, 1e-15);
}

// With a low max_condition the large networks lose their weakly regularised pairs while the
// small ones keep all: the candidates evaluate different numbers of C values, and every
// evaluated pair must still read its own sums.
TEST(Loo, SkippedPairsLeaveTheOthersExact) {
  const Problem p = MakeProblem(30, 2, 2, 20, 2);
  const std::vector<int> hidden_grid{1, 4, 10, 20};
  const std::vector<double> ridge_grid{0.01, 1.0, 100.0, 1e4};
  const Eigen::RowVectorXd scale = Eigen::RowVectorXd::Constant(2, 1.5);
  const double max_condition = 1e3;
  const std::vector<LooCandidate> candidates =
      RunLoo(p, hidden_grid, ridge_grid, max_condition, scale, 1);
  ASSERT_EQ(candidates.size(), 16u);
  std::vector<int> evaluated_per_l(hidden_grid.size(), 0);
  for (size_t k = 0; k < candidates.size(); ++k) {
    const LooCandidate& cand = candidates[k];
    const double cond = Condition(p.h, cand.hidden_units, cand.ridge_c);
    EXPECT_EQ(cand.skipped, cond > max_condition)
        << "L=" << cand.hidden_units << " C=" << cand.ridge_c << " cond " << cond;
    if (cand.skipped) {
      EXPECT_TRUE(std::isnan(cand.loo_mse));
      EXPECT_TRUE(std::isnan(cand.loo_rmse));
    } else {
      ExpectMatchesBruteForce(cand, p, scale);
      ++evaluated_per_l[k / ridge_grid.size()];
    }
  }
  // The case this test is about: a mix of full, partial and (possibly) empty candidates.
  EXPECT_EQ(evaluated_per_l.front(), 4);
  EXPECT_LT(evaluated_per_l.back(), 4);
  EXPECT_GT(evaluated_per_l.back() + evaluated_per_l[2], 0);
}

// 8292 rows are three row blocks. The PRESS errors equal the dense closed form
// e = (t - P t) / (1 - diag P), P = H (H^T H + I/C)^{-1} H^T by LLT (no eigendecomposition), and
// 1, 2 and 3 threads give the same bits.
TEST(Loo, ManyRowBlocksMatchTheDenseFormForAnyThreadCount) {
  const Problem p = MakeProblem(8292, 3, 1, 30, 3);
  const std::vector<int> hidden_grid{5, 30};
  const std::vector<double> ridge_grid{0.1, 10.0};
  const Eigen::RowVectorXd scale = Eigen::RowVectorXd::Constant(1, 3.0);
  const std::vector<LooCandidate> one = RunLoo(p, hidden_grid, ridge_grid, 1e12, scale, 1);
  ASSERT_EQ(one.size(), 4u);
  for (const LooCandidate& cand : one) {
    ASSERT_FALSE(cand.skipped);
    const Eigen::MatrixXd h = p.h.leftCols(cand.hidden_units);
    Eigen::MatrixXd system = h.transpose() * h;
    system.diagonal().array() += 1.0 / cand.ridge_c;
    const Eigen::LLT<Eigen::MatrixXd> llt(system);
    const Eigen::MatrixXd s = llt.solve(h.transpose());  // L x N
    const Eigen::VectorXd hat = h.cwiseProduct(s.transpose()).rowwise().sum();
    const Eigen::VectorXd fitted = h * (s * p.ts);
    const Eigen::VectorXd e =
        (p.ts.col(0) - fitted).cwiseQuotient((Eigen::VectorXd::Ones(h.rows()) - hat));
    const double mse = e.squaredNorm() / static_cast<double>(h.rows());
    EXPECT_NEAR(cand.loo_mse, mse, 1e-9 * mse) << "L=" << cand.hidden_units;
    EXPECT_NEAR(cand.loo_rmse, 3.0 * std::sqrt(mse), 1e-9 * 3.0 * std::sqrt(mse));
  }
  for (int threads : {2, 3}) {
    const std::vector<LooCandidate> other =
        RunLoo(p, hidden_grid, ridge_grid, 1e12, scale, threads);
    ASSERT_EQ(other.size(), one.size());
    for (size_t k = 0; k < one.size(); ++k) {
      EXPECT_EQ(std::memcmp(&one[k].loo_mse, &other[k].loo_mse, sizeof(double)), 0)
          << threads << " threads, pair " << k;
      EXPECT_EQ(std::memcmp(&one[k].condition, &other[k].condition, sizeof(double)), 0);
    }
  }
}

// elm::Fit with auto selection: the chosen (L, C) has the smallest brute-force leave-one-out
// error of the grid, and the model is the fixed fit at that pair. Noisy targets, so that the
// largest, least regularised network overfits and the choice is inside the grid.
TEST(Loo, AutoSelectionMinimisesTheBruteForceError) {
  const Problem p = MakeProblem(30, 2, 1, 20, 4, 0.5);
  const ElmOptions options{.hidden_units = 20,
                           .selection = Selection::kAuto,
                           .hidden_unit_candidates = {2, 5, 10, 20},
                           .ridge_c_candidates = {0.01, 0.1, 1.0, 10.0, 100.0},
                           .standardize_inputs = false,
                           .standardize_targets = false,
                           .seed = 3};
  const ElmFit fit = Fit(p.xs, p.ts, options);
  double best = std::numeric_limits<double>::infinity();
  int best_l = 0;
  double best_c = 0.0;
  for (int l : options.hidden_unit_candidates) {
    for (double c : options.ridge_c_candidates) {
      const double mse = BruteForceSse(p.h, p.ts, l, c).sum() / 30.0;
      if (mse < best) {
        best = mse;
        best_l = l;
        best_c = c;
      }
    }
  }
  EXPECT_EQ(fit.report.hidden_units, best_l);
  EXPECT_EQ(fit.report.ridge_c, best_c);
  EXPECT_NEAR(fit.report.loo_rmse, std::sqrt(best), 1e-10 * std::sqrt(best));
  // By construction of the problem, neither the largest nor the smallest pair: the criterion
  // decides something.
  EXPECT_FALSE(best_l == 20 && best_c == 100.0);
  EXPECT_FALSE(best_l == 2 && best_c == 0.01);
  ElmOptions fixed = options;
  fixed.selection = Selection::kFixed;
  fixed.hidden_units = best_l;
  fixed.ridge_c = best_c;
  const ElmModel direct = Fit(p.xs, p.ts, fixed).model;
  EXPECT_EQ(fit.model.num_hidden(), best_l);
  EXPECT_LT((fit.model.output_weights - direct.output_weights).norm(),
            1e-10 * direct.output_weights.norm());
}

// A constant target is fitted exactly by every pair (leave-one-out error 0 everywhere): the tie
// goes to the smallest network, then to the smallest C (the strongest regularisation).
TEST(Loo, TiesGoToTheSmallerNetworkThenTheStrongerRidge) {
  const Problem p = MakeProblem(40, 2, 1, 20, 5);
  const Eigen::MatrixXd t = Eigen::MatrixXd::Constant(40, 1, 7.5);
  const ElmFit fit = Fit(p.xs, t,
                         {.hidden_units = 20,
                          .selection = Selection::kAuto,
                          .hidden_unit_candidates = {3, 8, 20},
                          .ridge_c_candidates = {0.1, 1.0, 10.0}});
  for (const LooCandidate& cand : fit.report.candidates) EXPECT_EQ(cand.loo_mse, 0.0);
  EXPECT_EQ(fit.report.hidden_units, 3);
  EXPECT_EQ(fit.report.ridge_c, 0.1);
}

}  // namespace
}  // namespace gyrodrift::elm::internal
