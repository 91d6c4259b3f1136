// The polynomial learner (learner_poly.cc): exact recovery of a polynomial, coefficients that are
// the polynomial rewritten in standardised units, the graded monomial order, the degree deciding
// which polynomials are representable (there is no automatic order selection: the degree is an
// option), degree 1 as ordinary least squares, rank deficiency and the ridge, determinism, the
// term cap, and Load's checks of the monomial layout.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/learner.h"
#include "unit/drift/learner_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Data;
using fixtures::OptionsOf;
using fixtures::SameBits;
using fixtures::SineBowl;

// Population mean and standard deviation, the statistics the learner standardises with.
double Mean(const Eigen::VectorXd& v) { return v.mean(); }
double PopulationSd(const Eigen::VectorXd& v) {
  return std::sqrt((v.array() - v.mean()).square().mean());
}

TEST(LearnerPoly, PolyRecoversAnExactPolynomial) {
  // A quadratic in raw, offset inputs is a quadratic in the standardised ones.
  Rng rng(15, 0);
  const int n = 80;
  Eigen::MatrixXd x(n, 2);
  Eigen::VectorXd y(n);
  auto f = [](double a, double b) {
    return 1.0 + 2.0 * a - 3.0 * b + 0.5 * a * b + 0.25 * a * a - b * b;
  };
  for (int i = 0; i < n; ++i) {
    x(i, 0) = rng.Uniform(20.0, 30.0);  // a temperature in degrees C
    x(i, 1) = rng.Uniform(-1.0, 1.0);
    y[i] = f(x(i, 0), x(i, 1));
  }
  Eigen::MatrixXd probe(5, 2);
  probe << 21.0, 0.5, 25.0, -0.9, 29.5, 0.0, 22.2, 0.3, 27.0, -0.1;
  for (double ridge : {0.0, 1e-10}) {
    LearnerOptions o = OptionsOf(LearnerKind::kPoly);
    o.poly_degree = 2;
    o.poly_ridge = ridge;
    const auto learner = FitLearner(x, y, o);
    const Eigen::VectorXd p = learner->Predict(probe);
    for (Eigen::Index i = 0; i < probe.rows(); ++i) {
      EXPECT_NEAR(p[i], f(probe(i, 0), probe(i, 1)), 1e-8) << "ridge " << ridge;
    }
    EXPECT_EQ(learner->Save().arrays.at("coefficients").rows(), 6);  // C(4, 2)
  }
  // Degree 1 cannot represent it: the training error is visible.
  LearnerOptions o1 = OptionsOf(LearnerKind::kPoly);
  o1.poly_degree = 1;
  EXPECT_GT(FitLearner(x, y, o1)->Save().scalars.at("train_rmse"), 0.1);
}

TEST(LearnerPoly, PolyRejectsTooManyTerms) {
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(40, 30);
  const Eigen::VectorXd y = Eigen::VectorXd::Random(40);
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.poly_degree = 4;  // C(34, 4) = 46376 terms
  try {
    FitLearner(x, y, o);
    ADD_FAILURE() << "46376 terms accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("poly_degree"), std::string::npos) << e.what();
  }
  o.poly_degree = 2;  // C(32, 2) = 496 terms: fine (ridge keeps N < terms solvable)
  EXPECT_EQ(FitLearner(x, y, o)->Save().arrays.at("coefficients").rows(), 496);
}

// y = a + b x + c x^2 with x = m + s z and y = y_mean + y_sd y_s is, in standardised units,
// y_s = [(a + b m + c m^2 - y_mean) + (b + 2 c m) s z + c s^2 z^2] / y_sd: the saved
// coefficients must be exactly these (degree 0, 1, 2 in that order).
TEST(LearnerPoly, CoefficientsAreThePolynomialInStandardisedUnits) {
  const double a = -4.0, b = 0.7, c = 0.03;
  Rng rng(31, 0);
  Eigen::MatrixXd x(60, 1);
  Eigen::VectorXd y(60);
  for (int i = 0; i < 60; ++i) {
    x(i, 0) = rng.Uniform(20.0, 30.0);
    y[i] = a + b * x(i, 0) + c * x(i, 0) * x(i, 0);
  }
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.poly_degree = 2;
  o.poly_ridge = 0.0;
  const Parameters p = FitLearner(x, y, o)->Save();
  const double m = Mean(x.col(0)), s = PopulationSd(x.col(0));
  const double y_mean = Mean(y), y_sd = PopulationSd(y);
  const Eigen::Vector3d expected((a + b * m + c * m * m - y_mean) / y_sd,
                                 (b + 2.0 * c * m) * s / y_sd, c * s * s / y_sd);
  const Eigen::MatrixXd& coefficients = p.arrays.at("coefficients");
  ASSERT_EQ(coefficients.rows(), 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(coefficients(k, 0), expected[k], 1e-10) << "term " << k;
  }
  EXPECT_EQ(p.arrays.at("exponents"), (Eigen::MatrixXd(3, 1) << 0, 1, 2).finished());
  EXPECT_EQ(p.scalars.at("rank"), 3.0);
  EXPECT_LT(p.scalars.at("train_rmse"), 1e-10);
}

// Exponent rows: graded (total degree non-decreasing), within a degree in descending
// lexicographic order, each monomial exactly once, C(d + degree, degree) of them; and Predict
// is sum_k c_k prod_j z_j^e_kj mapped back to target units.
TEST(LearnerPoly, MonomialsAreGradedAndPredictEvaluatesThem) {
  const Data train = SineBowl(200, 0.05, 32);
  Eigen::MatrixXd x(200, 3);
  x << train.x, train.x.col(0).cwiseProduct(train.x.col(1));
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.poly_degree = 3;
  const auto learner = FitLearner(x, train.y, o);
  const Parameters p = learner->Save();
  const Eigen::MatrixXd& e = p.arrays.at("exponents");
  ASSERT_EQ(e.rows(), 20);  // C(6, 3)
  ASSERT_EQ(e.cols(), 3);
  EXPECT_EQ(e.row(0), Eigen::RowVector3d::Zero());
  EXPECT_EQ(e.row(1), Eigen::RowVector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(e.row(3), Eigen::RowVector3d(0.0, 0.0, 1.0));
  for (Eigen::Index k = 1; k < e.rows(); ++k) {
    const double previous = e.row(k - 1).sum(), current = e.row(k).sum();
    EXPECT_LE(previous, current) << "row " << k;
    if (previous == current) {
      const Eigen::RowVectorXd u_row = e.row(k - 1), v_row = e.row(k);
      const std::vector<double> u(u_row.data(), u_row.data() + u_row.size());
      const std::vector<double> v(v_row.data(), v_row.data() + v_row.size());
      EXPECT_GT(u, v) << "row " << k << " is not after row " << k - 1 << " in descending order";
    }
    EXPECT_LE(current, 3.0);
  }
  // By hand from the saved state, with std::pow.
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean"), scale = p.arrays.at("input_scale");
  const Eigen::MatrixXd& c = p.arrays.at("coefficients");
  const Data test = SineBowl(30, 0.0, 33);
  Eigen::MatrixXd xt(30, 3);
  xt << test.x, test.x.col(0).cwiseProduct(test.x.col(1));
  const Eigen::VectorXd predicted = learner->Predict(xt);
  for (Eigen::Index i = 0; i < xt.rows(); ++i) {
    const Eigen::RowVectorXd z = (xt.row(i) - mean).cwiseQuotient(scale);
    double y_s = 0.0;
    for (Eigen::Index k = 0; k < e.rows(); ++k) {
      double term = c(k, 0);
      for (Eigen::Index j = 0; j < 3; ++j) term *= std::pow(z[j], e(k, j));
      y_s += term;
    }
    const double y = y_s * p.arrays.at("target_scale")(0, 0) + p.arrays.at("target_mean")(0, 0);
    EXPECT_NEAR(predicted[i], y, 1e-12 * (1.0 + std::abs(y))) << "row " << i;
  }
}

// The degree decides what is representable: a cubic is fitted exactly from degree 3 on (the
// degree-4 term then vanishes) and not below.
TEST(LearnerPoly, DegreeDecidesWhichPolynomialsAreRecovered) {
  Rng rng(34, 0);
  Eigen::MatrixXd x(100, 1);
  Eigen::VectorXd y(100);
  for (int i = 0; i < 100; ++i) {
    x(i, 0) = rng.Uniform(-2.0, 3.0);
    const double v = x(i, 0);
    y[i] = 0.5 - v + 0.25 * v * v + 0.4 * v * v * v;
  }
  const double y_sd = PopulationSd(y);
  for (int degree = 1; degree <= 4; ++degree) {
    LearnerOptions o = OptionsOf(LearnerKind::kPoly);
    o.poly_degree = degree;
    o.poly_ridge = 0.0;
    const Parameters p = FitLearner(x, y, o)->Save();
    ASSERT_EQ(p.arrays.at("coefficients").rows(), degree + 1);
    const double rmse = p.scalars.at("train_rmse");
    if (degree < 3) {
      EXPECT_GT(rmse, 0.01 * y_sd) << "degree " << degree;
    } else {
      EXPECT_LT(rmse, 1e-9 * y_sd) << "degree " << degree;
    }
    if (degree == 4) {
      EXPECT_NEAR(p.arrays.at("coefficients")(4, 0), 0.0, 1e-9);
    }
  }
}

// Degree 1 is ordinary least squares with an intercept, which does not care how the inputs are
// scaled: the same predictions as a QR solve on the raw inputs.
TEST(LearnerPoly, DegreeOneIsOrdinaryLeastSquares) {
  const Data train = SineBowl(150, 0.1, 35);
  Eigen::MatrixXd x = train.x;
  x.col(1).array() = 25.0 + 3.0 * x.col(1).array();
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.poly_degree = 1;
  o.poly_ridge = 0.0;
  const auto learner = FitLearner(x, train.y, o);
  Eigen::MatrixXd design(150, 3);
  design << Eigen::VectorXd::Ones(150), x;
  const Eigen::VectorXd beta = design.householderQr().solve(train.y);
  const Eigen::VectorXd expected = design * beta;
  const Eigen::VectorXd predicted = learner->Predict(x);
  EXPECT_LT((predicted - expected).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(learner->Save().scalars.at("train_rmse"), fixtures::Rmse(expected, train.y), 1e-12);
}

// Two identical input columns make the design rank deficient. Without a ridge the pivoting QR
// reports the rank and still fits; with a ridge the system has full rank and the symmetric
// penalty splits the weight equally between the twins.
TEST(LearnerPoly, RankDeficientDesignIsReportedAndTheRidgeSplitsTwins) {
  Rng rng(36, 0);
  Eigen::MatrixXd x(50, 2);
  Eigen::VectorXd y(50);
  for (int i = 0; i < 50; ++i) {
    x(i, 0) = x(i, 1) = rng.Uniform(-1.0, 1.0);
    y[i] = 1.0 + 3.0 * x(i, 0);
  }
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.poly_degree = 1;
  o.poly_ridge = 0.0;
  const auto plain = FitLearner(x, y, o);
  EXPECT_EQ(plain->Save().scalars.at("rank"), 2.0);
  EXPECT_NE(plain->Summary().find("(rank 2)"), std::string::npos) << plain->Summary();
  EXPECT_LT((plain->Predict(x) - y).cwiseAbs().maxCoeff(), 1e-10);

  o.poly_ridge = 1e-6;
  const auto ridge = FitLearner(x, y, o);
  const Parameters p = ridge->Save();
  EXPECT_EQ(p.scalars.at("rank"), 3.0);
  EXPECT_EQ(ridge->Summary().find("rank"), std::string::npos) << ridge->Summary();
  const Eigen::MatrixXd& c = p.arrays.at("coefficients");
  EXPECT_NEAR(c(1, 0), c(2, 0), 1e-9 * std::abs(c(1, 0)));
  EXPECT_LT((ridge->Predict(x) - y).cwiseAbs().maxCoeff(), 1e-4);
}

// The fit draws no random numbers: the seed is only recorded.
TEST(LearnerPoly, SeedChangesNothingButTheRecord) {
  const Data train = SineBowl(120, 0.05, 37);
  LearnerOptions o = OptionsOf(LearnerKind::kPoly);
  o.seed = 1;
  const Parameters a = FitLearner(train.x, train.y, o)->Save();
  o.seed = 987654321987654321ULL;
  const Parameters b = FitLearner(train.x, train.y, o)->Save();
  EXPECT_TRUE(SameBits(a.arrays.at("coefficients"), b.arrays.at("coefficients")));
  EXPECT_EQ(b.texts.at("seed"), "987654321987654321");
}

TEST(LearnerPoly, LoadRejectsAnyOtherMonomialLayout) {
  const Data train = SineBowl(80, 0.05, 38);
  const Parameters saved = FitLearner(train.x, train.y, OptionsOf(LearnerKind::kPoly))->Save();
  Parameters swapped = saved;
  swapped.arrays["exponents"].row(1).swap(swapped.arrays["exponents"].row(2));
  EXPECT_THROW(LoadLearner(LearnerKind::kPoly, swapped), DataError);
  Parameters degree = saved;
  degree.scalars["degree"] = 2;  // 10 exponent rows are C(5, 3), not C(4, 2) = 6
  EXPECT_THROW(LoadLearner(LearnerKind::kPoly, degree), DataError);
  degree.scalars["degree"] = 5;
  EXPECT_THROW(LoadLearner(LearnerKind::kPoly, degree), DataError);
  Parameters ridge = saved;
  ridge.scalars["ridge"] = 2.0;
  EXPECT_THROW(LoadLearner(LearnerKind::kPoly, ridge), DataError);
  Parameters rank = saved;
  rank.scalars["rank"] = 11;
  EXPECT_THROW(LoadLearner(LearnerKind::kPoly, rank), DataError);
  EXPECT_NO_THROW(LoadLearner(LearnerKind::kPoly, saved));
}

}  // namespace
}  // namespace gyrodrift::drift
