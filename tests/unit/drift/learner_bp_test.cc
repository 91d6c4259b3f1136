// The BP learner (learner_bp.cc): RPROP training reduces the error on a smooth target, the
// epoch cap and the early stop, Predict as the documented tanh network on the saved weights,
// the seeded initial weights (one RPROP step away from the draw of Rng(seed, k)), the same seed
// giving the same bits for any thread count and other seeds other networks, and Load's checks of
// the layer layout.
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

// The standardised training MSE FANN reports is that of the weights before the last epoch's
// update, so one epoch reports the untrained network's error.
TEST(LearnerBp, TrainingReducesTheError) {
  const Data train = SineBowl(300, 0.05, 51);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_desired_mse = 0.0;
  std::vector<double> mse, rmse;
  for (int epochs : {1, 20, 300}) {
    o.bp_epochs = epochs;
    const Parameters p = FitLearner(train.x, train.y, o)->Save();
    mse.push_back(p.scalars.at("train_mse"));
    rmse.push_back(p.scalars.at("train_rmse"));
  }
  EXPECT_LT(rmse[1], rmse[0]);
  EXPECT_LT(rmse[2], rmse[1]);
  EXPECT_LT(mse[2], 0.1 * mse[0]);
  // After 300 epochs the fit explains almost all of the target's variance.
  const double y_sd = std::sqrt((train.y.array() - train.y.mean()).square().mean());
  EXPECT_LT(rmse[2], 0.1 * y_sd);
  const Data test = SineBowl(200, 0.0, 52);
  EXPECT_LT(fixtures::Rmse(FitLearner(train.x, train.y, o)->Predict(test.x), test.truth),
            0.15 * y_sd);
}

TEST(LearnerBp, BpStopsAtTheDesiredMseOrTheEpochCap) {
  const Data train = SineBowl(200, 0.05, 19);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_epochs = 7;
  o.bp_desired_mse = 0.0;
  EXPECT_EQ(FitLearner(train.x, train.y, o)->Save().scalars.at("epochs"), 7.0);
  o.bp_epochs = 5000;
  o.bp_desired_mse = 0.05;  // reached long before 5000 epochs
  const Parameters p = FitLearner(train.x, train.y, o)->Save();
  EXPECT_LT(p.scalars.at("epochs"), 5000.0);
  EXPECT_LE(p.scalars.at("train_mse"), 0.05);
  // Our forward pass is FANN's network: its training MSE (weights before the last RPROP
  // step, standardised units) matches the MSE of Predict on the training rows.
  o.bp_epochs = 200;
  o.bp_desired_mse = 0.0;
  const Parameters r = FitLearner(train.x, train.y, o)->Save();
  const double scale = r.arrays.at("target_scale")(0, 0);
  const double own_mse = std::pow(r.scalars.at("train_rmse") / scale, 2);
  EXPECT_NEAR(own_mse, r.scalars.at("train_mse"), 0.02 * r.scalars.at("train_mse"));
  // Two hidden layers: the saved layout follows the options.
  o.bp_hidden = {6, 4};
  o.bp_epochs = 50;
  const Parameters q = FitLearner(train.x, train.y, o)->Save();
  EXPECT_EQ(q.arrays.at("layer_sizes"), (Eigen::MatrixXd(1, 4) << 2, 6, 4, 1).finished());
  EXPECT_EQ(q.arrays.at("weights_2").rows(), 4);
  EXPECT_EQ(q.arrays.at("weights_2").cols(), 7);
}

// Hidden layers are FANN's SIGMOID_SYMMETRIC at steepness 0.5, i.e. tanh(0.5 u); the output is
// linear: recomputed from the saved weights (bias in the last column) with std::tanh.
TEST(LearnerBp, PredictIsTheTanhNetworkOfTheSavedWeights) {
  const Data train = SineBowl(150, 0.05, 53);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_hidden = {6, 4};
  o.bp_epochs = 60;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  const Eigen::RowVectorXd mean = p.arrays.at("input_mean"), scale = p.arrays.at("input_scale");
  const Data test = SineBowl(30, 0.0, 54);
  const Eigen::VectorXd predicted = learner->Predict(test.x);
  for (Eigen::Index i = 0; i < test.x.rows(); ++i) {
    Eigen::VectorXd a = (test.x.row(i) - mean).cwiseQuotient(scale).transpose();
    for (int k = 1; k <= 3; ++k) {
      const Eigen::MatrixXd& w = p.arrays.at("weights_" + std::to_string(k));
      const Eigen::VectorXd u = w.leftCols(w.cols() - 1) * a + w.col(w.cols() - 1);
      a = k < 3 ? Eigen::VectorXd((0.5 * u).array().tanh()) : u;
    }
    const double y = a[0] * p.arrays.at("target_scale")(0, 0) + p.arrays.at("target_mean")(0, 0);
    EXPECT_NEAR(predicted[i], y, 1e-12 * (1.0 + std::abs(y))) << "row " << i;
  }
}

// The initial weights of layer k are drawn row by row from Rng(seed, k), U[-r, r] with
// r = sqrt(3 / (n_{k-1} + 1)). One RPROP epoch moves every weight by the same initial step
// (FANN's delta_zero times its increase factor, whatever their values), so after one epoch each
// weight is exactly that step away from its draw. A wrong stream, order or range would leave
// distances of every size.
TEST(LearnerBp, InitialWeightsAreDrawnFromTheSeed) {
  const Data train = SineBowl(100, 0.05, 55);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_hidden = {5};
  o.bp_epochs = 1;
  o.bp_desired_mse = 0.0;
  o.seed = 77;
  const Parameters p = FitLearner(train.x, train.y, o)->Save();
  const std::vector<int> sizes{2, 5, 1};
  std::vector<double> steps;
  for (int k = 1; k <= 2; ++k) {
    const Eigen::MatrixXd& w = p.arrays.at("weights_" + std::to_string(k));
    ASSERT_EQ(w.rows(), sizes[k]);
    ASSERT_EQ(w.cols(), sizes[k - 1] + 1);
    Rng rng(77, static_cast<std::uint64_t>(k));
    const double r = std::sqrt(3.0 / (sizes[k - 1] + 1));
    for (Eigen::Index t = 0; t < w.rows(); ++t) {
      for (Eigen::Index j = 0; j < w.cols(); ++j)
        steps.push_back(std::abs(w(t, j) - rng.Uniform(-r, r)));
    }
  }
  ASSERT_EQ(steps.size(), 21u);
  EXPECT_GT(steps[0], 0.0);
  EXPECT_LT(steps[0], 1.0);
  for (size_t c = 1; c < steps.size(); ++c) {
    EXPECT_NEAR(steps[c], steps[0], 1e-12) << "connection " << c;
  }
}

// Same seed: the same network to the bit, with 1 or 2 threads; other seeds: other networks.
TEST(LearnerBp, SeedReproducesAndDifferentSeedsDiffer) {
  const Data train = SineBowl(200, 0.05, 11);
  const Data test = SineBowl(100, 0.0, 12);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_epochs = 100;
  o.seed = 5;
  const auto a = FitLearner(train.x, train.y, o, {.threads = 2});
  const auto b = FitLearner(train.x, train.y, o, {.threads = 1});
  o.seed = 6;
  const auto c = FitLearner(train.x, train.y, o);
  const Parameters pa = a->Save(), pb = b->Save(), pc = c->Save();
  for (const char* name : {"weights_1", "weights_2"}) {
    EXPECT_TRUE(SameBits(pa.arrays.at(name), pb.arrays.at(name))) << name;
    EXPECT_FALSE(SameBits(pa.arrays.at(name), pc.arrays.at(name))) << name;
  }
  EXPECT_TRUE(SameBits(a->Predict(test.x), b->Predict(test.x)));
  EXPECT_GT((a->Predict(test.x) - c->Predict(test.x)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(LearnerBp, LoadRejectsABrokenLayerLayout) {
  const Data train = SineBowl(60, 0.05, 56);
  LearnerOptions o = OptionsOf(LearnerKind::kBp);
  o.bp_epochs = 5;
  const Parameters saved = FitLearner(train.x, train.y, o)->Save();
  EXPECT_NO_THROW(LoadLearner(LearnerKind::kBp, saved));
  Parameters two_outputs = saved;
  two_outputs.arrays["layer_sizes"](0, 2) = 2;
  EXPECT_THROW(LoadLearner(LearnerKind::kBp, two_outputs), DataError);
  Parameters fractional = saved;
  fractional.arrays["layer_sizes"](0, 1) = 9.5;
  EXPECT_THROW(LoadLearner(LearnerKind::kBp, fractional), DataError);
  Parameters no_hidden = saved;
  no_hidden.arrays["layer_sizes"] = (Eigen::MatrixXd(1, 2) << 2, 1).finished();
  EXPECT_THROW(LoadLearner(LearnerKind::kBp, no_hidden), DataError);
  Parameters epochs = saved;
  epochs.scalars["epochs"] = 2.5;
  EXPECT_THROW(LoadLearner(LearnerKind::kBp, epochs), DataError);
}

}  // namespace
}  // namespace gyrodrift::drift
