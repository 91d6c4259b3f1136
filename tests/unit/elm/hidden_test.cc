// The ELM's hidden layer (src/elm/hidden.cc): hidden units drawn from (seed, unit index) alone,
// so they are nested, reproducible, different for other seeds and independent of the thread
// count; the value of each activation against its formula; the streamed Gram matrix against a
// dense product and to the bit for any thread count; and the Cholesky ridge solver against an
// independent solve, its condition estimate and its LDLT fallback.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "elm/training.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::elm::internal {
namespace {

bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

Eigen::MatrixXd Uniform(Eigen::Index rows, Eigen::Index cols, double lo, double hi,
                        std::uint64_t seed) {
  Rng rng(seed, 0);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.Uniform(lo, hi);
  return m;
}

// Unit j: d weights U[-1, 1] then its bias U[0, 1], all from Rng(seed, j).
TEST(Hidden, UnitJIsDrawnFromRngSeedJ) {
  Eigen::MatrixXd w;
  Eigen::VectorXd b;
  DrawUnits(3, 7, 42, &w, &b);
  ASSERT_EQ(w.rows(), 3);
  ASSERT_EQ(w.cols(), 7);
  ASSERT_EQ(b.size(), 7);
  for (int j = 0; j < 7; ++j) {
    Rng rng(42, static_cast<std::uint64_t>(j));
    for (int i = 0; i < 3; ++i) EXPECT_EQ(w(i, j), rng.Uniform(-1.0, 1.0)) << i << ", " << j;
    EXPECT_EQ(b[j], rng.Uniform()) << j;
  }
}

// Because unit j depends on (seed, j) only, the first L units of a larger draw are the draw of
// L units, and a fit with auto selection keeps a prefix of its largest candidate.
TEST(Hidden, UnitsAreNestedAndInRange) {
  Eigen::MatrixXd w_small, w_large;
  Eigen::VectorXd b_small, b_large;
  DrawUnits(4, 5, 9, &w_small, &b_small);
  DrawUnits(4, 300, 9, &w_large, &b_large);
  EXPECT_TRUE(SameBits(w_small, w_large.leftCols(5)));
  EXPECT_TRUE(SameBits(b_small, b_large.head(5)));
  EXPECT_GE(w_large.minCoeff(), -1.0);
  EXPECT_LT(w_large.maxCoeff(), 1.0);
  EXPECT_GE(b_large.minCoeff(), 0.0);
  EXPECT_LT(b_large.maxCoeff(), 1.0);
  // 1200 draws fill the ranges: not a narrower or shifted interval.
  EXPECT_LT(w_large.minCoeff(), -0.99);
  EXPECT_GT(w_large.maxCoeff(), 0.99);
  EXPECT_LT(b_large.minCoeff(), 0.01);
  EXPECT_GT(b_large.maxCoeff(), 0.99);
  EXPECT_NEAR(w_large.mean(), 0.0, 0.05);
  EXPECT_NEAR(b_large.mean(), 0.5, 0.05);
}

// Other seeds give other units, and (seed, j) is not confused with (seed', j') for seed + j =
// seed' + j' (a derivation such as Rng(seed + j, 0) would make these equal).
TEST(Hidden, DifferentSeedsGiveDifferentUnits) {
  Eigen::MatrixXd w1, w2;
  Eigen::VectorXd b1, b2;
  DrawUnits(2, 10, 1, &w1, &b1);
  DrawUnits(2, 10, 2, &w2, &b2);
  for (Eigen::Index j = 0; j < 10; ++j) {
    EXPECT_NE(b1[j], b2[j]) << j;
    EXPECT_NE(w1(0, j), w2(0, j)) << j;
  }
  for (Eigen::Index j = 1; j < 10; ++j) {
    EXPECT_NE(w1(0, j), w2(0, j - 1))
        << "unit " << j << " of seed 1 is unit " << j - 1 << " of seed 2";
  }
}

// elm::Fit draws its units by the same rule, whatever the thread count; auto selection keeps the
// prefix of the chosen size.
TEST(Hidden, FittedUnitsDependOnTheSeedAloneNotTheThreads) {
  Rng rng(5, 0);
  Eigen::MatrixXd x(9000, 2);  // three row blocks
  Eigen::MatrixXd t(9000, 1);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    x(i, 0) = rng.Uniform(-2.0, 2.0);
    x(i, 1) = rng.Uniform(10.0, 20.0);
    t(i, 0) = std::sin(x(i, 0)) + 0.1 * x(i, 1) + 0.05 * rng.Normal();
  }
  Eigen::MatrixXd w;
  Eigen::VectorXd b;
  DrawUnits(2, 40, 123, &w, &b);
  for (Selection selection : {Selection::kFixed, Selection::kAuto}) {
    const ElmOptions o{.hidden_units = 40, .selection = selection, .seed = 123};
    const ElmModel m1 = Fit(x, t, o, {.threads = 1}).model;
    const ElmModel m2 = Fit(x, t, o, {.threads = 2}).model;
    const Eigen::Index l = m1.num_hidden();
    EXPECT_TRUE(SameBits(m1.input_weights, w.leftCols(l))) << ToString(selection);
    EXPECT_TRUE(SameBits(m1.biases, b.head(l))) << ToString(selection);
    EXPECT_TRUE(SameBits(m1.input_weights, m2.input_weights)) << ToString(selection);
    EXPECT_TRUE(SameBits(m1.biases, m2.biases)) << ToString(selection);
  }
}

// Each activation against its formula in double precision with libm: sigmoid 1/(1 + e^-z),
// tanh z, sin z, linear z with z = x . a_j + b_j, and the Gaussian RBF exp(-b_j ||x - a_j||^2 / d),
// where b_j is an impact factor, not an offset. Three inputs, so a missing 1/d shows. Only the
// kernels' rounding (FMA, their polynomial exp) separates the two.
TEST(Hidden, ActivationsMatchTheirFormulas) {
  const Eigen::MatrixXd xs = Uniform(37, 3, -2.0, 2.0, 1);
  Eigen::MatrixXd w;
  Eigen::VectorXd b;
  DrawUnits(3, 9, 2, &w, &b);
  for (Activation activation : {Activation::kSigmoid, Activation::kTanh, Activation::kSine,
                                Activation::kRbf, Activation::kLinear}) {
    Eigen::MatrixXd h(37, 9);
    ComputeHidden(activation, xs, w, b, h);
    for (Eigen::Index i = 0; i < 37; ++i) {
      for (Eigen::Index j = 0; j < 9; ++j) {
        const double z = xs.row(i).dot(w.col(j)) + b[j];
        double expected = 0.0;
        switch (activation) {
          case Activation::kSigmoid:
            expected = 1.0 / (1.0 + std::exp(-z));
            break;
          case Activation::kTanh:
            expected = std::tanh(z);
            break;
          case Activation::kSine:
            expected = std::sin(z);
            break;
          case Activation::kRbf:
            expected = std::exp(-b[j] * (xs.row(i).transpose() - w.col(j)).squaredNorm() / 3.0);
            break;
          case Activation::kLinear:
            expected = z;
            break;
        }
        EXPECT_NEAR(h(i, j), expected, 1e-14 * (1.0 + std::abs(expected)))
            << ToString(activation) << " row " << i << " unit " << j;
      }
    }
  }
}

// `out` may be a block of a larger buffer: the block is written, its neighbours are not.
TEST(Hidden, WritesOnlyIntoTheGivenBlock) {
  const Eigen::MatrixXd xs = Uniform(11, 2, -1.0, 1.0, 3);
  Eigen::MatrixXd w;
  Eigen::VectorXd b;
  DrawUnits(2, 4, 4, &w, &b);
  Eigen::MatrixXd dense(11, 4);
  ComputeHidden(Activation::kTanh, xs, w, b, dense);
  const double sentinel = -123.5;
  Eigen::MatrixXd buffer = Eigen::MatrixXd::Constant(20, 7, sentinel);
  ComputeHidden(Activation::kTanh, xs, w, b, buffer.block(5, 2, 11, 4));
  EXPECT_TRUE(SameBits(buffer.block(5, 2, 11, 4), dense));
  Eigen::MatrixXd outside = buffer;
  outside.block(5, 2, 11, 4).setConstant(sentinel);
  EXPECT_TRUE((outside.array() == sentinel).all());
}

// H^T H (lower triangle, strict upper zero) and H^T T against dense products of the same H, and
// the same bits for 1, 2 and 3 threads over 9000 rows (three row blocks of 4096).
TEST(Hidden, GramIsHTransposeHForAnyThreadCount) {
  const Eigen::MatrixXd xs = Uniform(9000, 3, -2.0, 2.0, 5);
  const Eigen::MatrixXd ts = Uniform(9000, 2, -1.0, 1.0, 6);
  Eigen::MatrixXd w;
  Eigen::VectorXd b;
  DrawUnits(3, 25, 7, &w, &b);
  Eigen::MatrixXd h(9000, 25);
  ComputeHidden(Activation::kSigmoid, xs, w, b, h);
  const Gram g1 = ComputeGram(Activation::kSigmoid, xs, ts, w, b, 1);
  const Eigen::MatrixXd hth = h.transpose() * h;
  const Eigen::MatrixXd htt = h.transpose() * ts;
  const Eigen::MatrixXd lower = hth.triangularView<Eigen::Lower>();
  EXPECT_LT((g1.hth - lower).cwiseAbs().maxCoeff(), 1e-12 * hth.cwiseAbs().maxCoeff());
  EXPECT_EQ(Eigen::MatrixXd(g1.hth.triangularView<Eigen::StrictlyUpper>()).cwiseAbs().maxCoeff(),
            0.0);
  ASSERT_EQ(g1.htt.rows(), 25);
  ASSERT_EQ(g1.htt.cols(), 2);
  EXPECT_LT((g1.htt - htt).cwiseAbs().maxCoeff(), 1e-12 * htt.cwiseAbs().maxCoeff());
  for (int threads : {2, 3}) {
    const Gram g = ComputeGram(Activation::kSigmoid, xs, ts, w, b, threads);
    EXPECT_TRUE(SameBits(g.hth, g1.hth)) << threads << " threads";
    EXPECT_TRUE(SameBits(g.htt, g1.htt)) << threads << " threads";
  }
}

// beta solves (G_LL + I/C) beta = (H^T T)_L using only the leading L x L block of the lower
// triangle and the first L rows of H^T T: everything else is NaN here and must not be read.
TEST(Hidden, RidgeCholeskySolvesTheLeadingBlock) {
  const Eigen::MatrixXd a = Uniform(40, 6, -1.0, 1.0, 8);
  const Eigen::MatrixXd full = a.transpose() * a;
  const Eigen::MatrixXd rhs = Uniform(6, 2, -1.0, 1.0, 9);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd hth = full;
  hth.triangularView<Eigen::StrictlyUpper>().setConstant(nan);
  hth.bottomRows(2).setConstant(nan);
  hth.rightCols(2).setConstant(nan);
  hth.topLeftCorner(4, 4).triangularView<Eigen::Lower>() = full.topLeftCorner(4, 4);
  Eigen::MatrixXd htt = rhs;
  htt.bottomRows(2).setConstant(nan);
  const double c = 5.0;
  const RidgeSolution s = SolveRidgeCholesky(hth, htt, 4, c);
  const Eigen::MatrixXd system = full.topLeftCorner(4, 4) + Eigen::MatrixXd::Identity(4, 4) / c;
  const Eigen::MatrixXd expected = system.fullPivLu().solve(rhs.topRows(4));
  ASSERT_EQ(s.beta.rows(), 4);
  ASSERT_EQ(s.beta.cols(), 2);
  EXPECT_LT((s.beta - expected).norm(), 1e-13 * expected.norm());
  EXPECT_FALSE(s.ldlt_fallback);
  // 1 / rcond estimates cond_1 from below (Higham's estimator of ||A^-1||_1 is a lower bound).
  const double cond_1 = system.cwiseAbs().colwise().sum().maxCoeff() *
                        system.inverse().cwiseAbs().colwise().sum().maxCoeff();
  EXPECT_LE(s.condition, cond_1 * (1.0 + 1e-10));
  EXPECT_GE(s.condition, cond_1 / 4.0);
}

// On a diagonal system the estimate is exact: (max + 1/C) / (min + 1/C).
TEST(Hidden, RidgeConditionOfADiagonalSystem) {
  const Eigen::MatrixXd hth = Eigen::Vector3d(9.0, 0.5, 100.0).asDiagonal();
  const RidgeSolution s = SolveRidgeCholesky(hth, Eigen::MatrixXd::Ones(3, 1), 3, 10.0);
  EXPECT_NEAR(s.condition, 100.1 / 0.6, 1e-12 * 100.1 / 0.6);
  EXPECT_NEAR(s.beta(1, 0), 1.0 / 0.6, 1e-15);
}

// A system that is not positive definite (only rounding can make H^T H + I/C so) is solved by
// LDLT, and the report says so.
TEST(Hidden, RidgeFallsBackToLdltWhenNotPositiveDefinite) {
  Eigen::MatrixXd hth(2, 2);
  hth << 2.0, 0.0, 0.3, -1.0;  // lower triangle: [[2, 0.3], [0.3, -1]], indefinite
  const Eigen::MatrixXd htt = (Eigen::MatrixXd(2, 1) << 1.0, 2.0).finished();
  const RidgeSolution s = SolveRidgeCholesky(hth, htt, 2, 1e6);
  EXPECT_TRUE(s.ldlt_fallback);
  Eigen::MatrixXd system(2, 2);
  system << 2.0 + 1e-6, 0.3, 0.3, -1.0 + 1e-6;
  EXPECT_LT((system * s.beta - htt).norm(), 1e-14);
  EXPECT_TRUE(std::isfinite(s.condition));
}

}  // namespace
}  // namespace gyrodrift::elm::internal
