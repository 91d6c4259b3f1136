// The SVR learner (learner_svr.cc): a linear target fitted within the epsilon tube, the KKT
// structure of the support vectors (free ones on the tube, rows inside the tube none, the
// coefficients in the box and summing to zero), Predict as the documented RBF expansion, the
// evenly spaced subsample, a constant target with no support vectors, and reproducibility.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

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

// libsvm stops when the KKT violation is below 1e-3 (its default tolerance, learner_svr.cc), so
// the tube conditions hold to about that in standardised target units.
constexpr double kSolverTolerance = 2e-3;

// y = 3 + 2 x1 - x2 on [-1, 1]^2, no noise.
Data Plane(int n, std::uint64_t seed) {
  Rng rng(seed, 0);
  Data d;
  d.x.resize(n, 2);
  d.y.resize(n);
  for (int i = 0; i < n; ++i) {
    d.x(i, 0) = rng.Uniform(-1.0, 1.0);
    d.x(i, 1) = rng.Uniform(-1.0, 1.0);
    d.y[i] = 3.0 + 2.0 * d.x(i, 0) - d.x(i, 1);
  }
  d.truth = d.y;
  return d;
}

// Index of the training row whose standardised inputs are support vector s, or -1.
Eigen::Index RowOf(const Eigen::MatrixXd& x, const Parameters& p, Eigen::Index s) {
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean");
  const Eigen::RowVectorXd scale = p.arrays.at("input_scale");
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Eigen::RowVectorXd z = (x.row(i) - mean).cwiseQuotient(scale);
    if ((z - p.arrays.at("support_vectors").row(s)).cwiseAbs().maxCoeff() == 0.0) return i;
  }
  return -1;
}

// With a generous box (no coefficient at the bound) every training residual lies within the
// tube, |y_s - f| <= epsilon; test rows inside the sampled square stay close to the plane too.
TEST(LearnerSvr, FitsALinearTargetWithinTheTube) {
  const Data train = Plane(200, 41);
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.svr_c = 1000.0;
  o.svr_epsilon = 0.05;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  const double t_scale = p.arrays.at("target_scale")(0, 0);
  ASSERT_LT(p.arrays.at("coefficients").cwiseAbs().maxCoeff(), 0.99 * o.svr_c)
      << "a bounded support vector: the test needs a larger C";
  const Eigen::VectorXd residual_s = (train.y - learner->Predict(train.x)) / t_scale;
  EXPECT_LE(residual_s.cwiseAbs().maxCoeff(), o.svr_epsilon + kSolverTolerance);
  // Not a trivial fit: the tube is 5 % of the target's spread, and the spread is not small.
  EXPECT_GT(t_scale, 1.0);
  const Data test = Plane(100, 42);
  const Eigen::VectorXd test_residual_s = (test.y - learner->Predict(test.x)) / t_scale;
  EXPECT_LT(test_residual_s.cwiseAbs().maxCoeff(), 3.0 * o.svr_epsilon);
}

// KKT conditions of epsilon-SVR (Smola & Schoelkopf 2004): a row strictly inside the tube has
// alpha = alpha* = 0 (not a support vector), a support vector has |residual| >= epsilon, every
// coefficient alpha - alpha* lies in [-C, C], and the equality constraint makes them sum to 0.
TEST(LearnerSvr, SupportVectorsFollowTheKktConditions) {
  const Data train = SineBowl(250, 0.1, 43);
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.svr_c = 3.0;
  o.svr_epsilon = 0.1;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  const Eigen::MatrixXd& coef = p.arrays.at("coefficients");
  const double t_scale = p.arrays.at("target_scale")(0, 0);
  const Eigen::VectorXd residual_s = (train.y - learner->Predict(train.x)) / t_scale;
  ASSERT_GT(coef.rows(), 10);
  EXPECT_LE(coef.cwiseAbs().maxCoeff(), o.svr_c * (1.0 + 1e-12));
  EXPECT_NEAR(coef.sum(), 0.0, 1e-9 * o.svr_c * coef.rows());
  Eigen::VectorXi is_support = Eigen::VectorXi::Zero(train.x.rows());
  for (Eigen::Index s = 0; s < coef.rows(); ++s) {
    const Eigen::Index i = RowOf(train.x, p, s);
    ASSERT_GE(i, 0) << "support vector " << s << " is no training row";
    is_support[i] = 1;
    EXPECT_GE(std::abs(residual_s[i]), o.svr_epsilon - kSolverTolerance) << "row " << i;
  }
  int inside = 0;
  for (Eigen::Index i = 0; i < train.x.rows(); ++i) {
    if (std::abs(residual_s[i]) < o.svr_epsilon - kSolverTolerance) {
      EXPECT_EQ(is_support[i], 0) << "row " << i << " inside the tube is a support vector";
      ++inside;
    }
  }
  EXPECT_GT(inside, 10);
  // A wider tube holds more rows, so fewer need to be support vectors.
  o.svr_epsilon = 0.4;
  EXPECT_LT(FitLearner(train.x, train.y, o)->Save().arrays.at("support_vectors").rows(),
            coef.rows());
}

// The SVR expansion evaluated here is libsvm's decision function: at a free support vector
// (0 < |coef| < C) the KKT conditions put the residual exactly on the epsilon tube.
TEST(LearnerSvr, SvrFreeSupportVectorsSitOnTheEpsilonTube) {
  const Data train = SineBowl(300, 0.1, 16);
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.svr_c = 5.0;
  o.svr_epsilon = 0.1;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  const Eigen::MatrixXd& sv = p.arrays.at("support_vectors");
  const Eigen::MatrixXd& coef = p.arrays.at("coefficients");
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean");
  const Eigen::RowVectorXd scale = p.arrays.at("input_scale");
  const double t_mean = p.arrays.at("target_mean")(0, 0);
  const double t_scale = p.arrays.at("target_scale")(0, 0);
  ASSERT_GT(sv.rows(), 10);
  EXPECT_LT(sv.rows(), 300);  // the tube leaves some rows out
  const Eigen::VectorXd pred = learner->Predict(train.x);
  int free = 0;
  for (Eigen::Index s = 0; s < sv.rows(); ++s) {
    if (std::abs(coef(s, 0)) > 0.99 * o.svr_c) continue;  // bounded: residual outside the tube
    for (Eigen::Index i = 0; i < train.x.rows(); ++i) {
      const Eigen::RowVectorXd z = (train.x.row(i) - mean).cwiseQuotient(scale);
      if ((z - sv.row(s)).cwiseAbs().maxCoeff() > 1e-12) continue;
      const double residual_s = (train.y[i] - pred[i]) / t_scale;
      EXPECT_NEAR(std::abs(residual_s), o.svr_epsilon, 2e-3) << "support vector " << s;
      EXPECT_GT(residual_s * coef(s, 0), 0.0);  // above the tube pulls up, below pulls down
      ++free;
    }
  }
  EXPECT_GT(free, 3);
  (void)t_mean;
}

TEST(LearnerSvr, SvrTrainsOnAnEvenlySpacedSubsample) {
  const Data train = SineBowl(500, 0.05, 17);
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.svr_max_rows = 100;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  EXPECT_EQ(p.scalars.at("rows_used"), 100.0);
  EXPECT_EQ(p.scalars.at("train_rows"), 500.0);
  EXPECT_LE(p.arrays.at("support_vectors").rows(), 100);
  // Every support vector is one of rows 0, 5, 10, ... (standardised).
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean");
  const Eigen::RowVectorXd scale = p.arrays.at("input_scale");
  const Eigen::MatrixXd& sv = p.arrays.at("support_vectors");
  for (Eigen::Index s = 0; s < sv.rows(); ++s) {
    bool found = false;
    for (Eigen::Index i = 0; i < 500 && !found; ++i) {
      const Eigen::RowVectorXd z = (train.x.row(i) - mean).cwiseQuotient(scale);
      if ((z - sv.row(s)).cwiseAbs().maxCoeff() == 0.0) {
        found = true;
        EXPECT_EQ(i % 5, 0) << "support vector " << s << " is row " << i;
      }
    }
    EXPECT_TRUE(found) << "support vector " << s;
  }
  EXPECT_NE(learner->Summary().find("from 100 of 500 rows"), std::string::npos)
      << learner->Summary();
}

TEST(LearnerSvr, SvrConstantTargetHasNoSupportVectorsAndRoundTrips) {
  const Data train = SineBowl(40, 0.0, 18);
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(40, 3.25);
  const auto learner = FitLearner(train.x, y, OptionsOf(LearnerKind::kSvr));
  const Parameters p = learner->Save();
  const auto loaded = LoadLearner(LearnerKind::kSvr, p);
  const Eigen::VectorXd a = learner->Predict(train.x);
  EXPECT_TRUE(SameBits(a, loaded->Predict(train.x)));
  EXPECT_NEAR((a.array() - 3.25).abs().maxCoeff(), 0.0, 1e-9);
  EXPECT_EQ(p.arrays.at("support_vectors").rows(), 0);
  // A model file that loses the column count of the empty arrays still loads.
  Parameters flat = p;
  flat.arrays["support_vectors"].resize(0, 0);
  flat.arrays["coefficients"].resize(0, 0);
  EXPECT_TRUE(SameBits(a, LoadLearner(LearnerKind::kSvr, flat)->Predict(train.x)));
}

// Predict is y = (sum_s coef_s exp(-gamma ||z - sv_s||^2) - rho) * t_scale + t_mean on the
// standardised inputs, with gamma = 1 / #inputs by default.
TEST(LearnerSvr, PredictIsTheSavedRbfExpansion) {
  const Data train = SineBowl(200, 0.05, 44);
  const auto learner = FitLearner(train.x, train.y, OptionsOf(LearnerKind::kSvr));
  const Parameters p = learner->Save();
  EXPECT_EQ(p.scalars.at("gamma"), 0.5);
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean"), scale = p.arrays.at("input_scale");
  const Eigen::MatrixXd& sv = p.arrays.at("support_vectors");
  const Eigen::MatrixXd& coef = p.arrays.at("coefficients");
  const Data test = SineBowl(40, 0.0, 45);
  const Eigen::VectorXd predicted = learner->Predict(test.x);
  for (Eigen::Index i = 0; i < test.x.rows(); ++i) {
    const Eigen::RowVectorXd z = (test.x.row(i) - mean).cwiseQuotient(scale);
    const Eigen::VectorXd k = (-0.5 * (sv.rowwise() - z).rowwise().squaredNorm()).array().exp();
    const double y =
        (coef.col(0).dot(k) - p.scalars.at("rho")) * p.arrays.at("target_scale")(0, 0) +
        p.arrays.at("target_mean")(0, 0);
    EXPECT_NEAR(predicted[i], y, 1e-12 * (1.0 + std::abs(y))) << "row " << i;
  }
  // A given gamma is used as given.
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.svr_gamma = 2.0;
  EXPECT_EQ(FitLearner(train.x, train.y, o)->Save().scalars.at("gamma"), 2.0);
}

// libsvm's epsilon-SVR draws no random numbers, and prediction rows are independent, so fits
// repeat to the bit whatever the seed and the thread count.
TEST(LearnerSvr, FitsRepeatToTheBitForAnySeedAndThreadCount) {
  const Data train = SineBowl(300, 0.05, 46);
  const Data test = SineBowl(700, 0.0, 47);  // several prediction blocks
  LearnerOptions o = OptionsOf(LearnerKind::kSvr);
  o.seed = 3;
  const auto a = FitLearner(train.x, train.y, o, {.threads = 1});
  o.seed = 4;
  const auto b = FitLearner(train.x, train.y, o, {.threads = 2});
  const Parameters pa = a->Save(), pb = b->Save();
  EXPECT_TRUE(SameBits(pa.arrays.at("support_vectors"), pb.arrays.at("support_vectors")));
  EXPECT_TRUE(SameBits(pa.arrays.at("coefficients"), pb.arrays.at("coefficients")));
  EXPECT_EQ(pa.scalars.at("rho"), pb.scalars.at("rho"));
  EXPECT_TRUE(SameBits(a->Predict(test.x), b->Predict(test.x)));
}

}  // namespace
}  // namespace gyrodrift::drift
