// ELM: function recovery, exact interpolation, the ridge solution against independent closed
// forms, the training-only scaler, determinism across seeds and threads, and option checks.
#include "gyrodrift/elm/elm.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::elm {
namespace {

struct Data {
  Eigen::MatrixXd x;
  Eigen::MatrixXd t;      // noisy targets
  Eigen::MatrixXd truth;  // noise-free targets
};

// y = sin(x) + noise, x ~ U[-3, 3].
Data NoisySine(int n, double noise_sd, std::uint64_t seed) {
  Rng rng(seed, 0);
  Data d;
  d.x.resize(n, 1);
  d.t.resize(n, 1);
  d.truth.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    d.x(i, 0) = rng.Uniform(-3.0, 3.0);
    d.truth(i, 0) = std::sin(d.x(i, 0));
    d.t(i, 0) = d.truth(i, 0) + noise_sd * rng.Normal();
  }
  return d;
}

// Random inputs with a smooth multi-output target, for the algebra tests.
Data Smooth(int n, int inputs, int outputs, std::uint64_t seed) {
  Rng rng(seed, 1);
  Data d;
  d.x.resize(n, inputs);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < inputs; ++j) d.x(i, j) = rng.Uniform(-2.0, 2.0) + 3.0 * j;
  }
  d.t.resize(n, outputs);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < outputs; ++k) {
      d.t(i, k) = std::cos(d.x(i, 0) * (k + 1)) + 0.3 * d.x.row(i).sum() + 0.05 * rng.Normal();
    }
  }
  d.truth = d.t;
  return d;
}

double Rmse(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

template <class E>
std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a.data()[i], &b.data()[i], sizeof(double)) != 0) return false;
  }
  return true;
}

TEST(Elm, RecoversNoisySineNearTheNoiseLevel) {
  const double noise = 0.1;
  const Data train = NoisySine(2000, noise, 11);
  const Data test = NoisySine(1000, noise, 12);
  const ElmFit fit = Fit(train.x, train.t, {.hidden_units = 30});
  const Eigen::MatrixXd y = Predict(fit.model, test.x);
  // Against the noisy targets the RMSE cannot beat the noise; against the truth it is small.
  EXPECT_LT(Rmse(y, test.t), 1.08 * noise);
  EXPECT_GT(Rmse(y, test.t), 0.9 * noise);
  EXPECT_LT(Rmse(y, test.truth), 0.03);
  EXPECT_NEAR(fit.report.train_rmse, noise, 0.01);
  EXPECT_EQ(fit.model.num_hidden(), 30);
  EXPECT_FALSE(fit.report.Summary().empty());
}

class ElmActivation : public ::testing::TestWithParam<Activation> {};

TEST_P(ElmActivation, FitsTheSineWithAutoSelection) {
  const Data train = NoisySine(1500, 0.1, 21);
  const Data test = NoisySine(800, 0.1, 22);
  const ElmFit fit =
      Fit(train.x, train.t,
          {.hidden_units = 100, .activation = GetParam(), .selection = Selection::kAuto});
  const double rmse = Rmse(Predict(fit.model, test.x), test.truth);
  if (GetParam() == Activation::kLinear) {
    // A random linear projection of one input is a straight line: it cannot follow sin on
    // [-3, 3], and auto selection must not pretend it does.
    EXPECT_GT(rmse, 0.2);
  } else {
    EXPECT_LT(rmse, 0.04) << ToString(GetParam()) << ": " << fit.report.Summary();
    EXPECT_NEAR(fit.report.loo_rmse, 0.1, 0.015) << fit.report.Summary();
  }
}

INSTANTIATE_TEST_SUITE_P(All, ElmActivation,
                         ::testing::Values(Activation::kSigmoid, Activation::kTanh,
                                           Activation::kSine, Activation::kRbf,
                                           Activation::kLinear),
                         [](const auto& info) { return std::string(ToString(info.param)); });

TEST(Elm, InterpolatesExactlyWhenUnitsExceedRowsWithoutRegularisation) {
  const Data d = Smooth(30, 2, 1, 31);
  const ElmOptions qr{.hidden_units = 60,
                      .ridge_c = std::numeric_limits<double>::infinity(),
                      .solver = Solver::kQr};
  const ElmFit fit = Fit(d.x, d.t, qr);
  EXPECT_EQ(fit.report.numerical_rank, 30);
  EXPECT_LT((Predict(fit.model, d.x) - d.t).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT(fit.report.train_rmse, 1e-9);

  // The ridge path approaches interpolation as C grows.
  double previous = std::numeric_limits<double>::infinity();
  double first = 0.0;
  for (double c : {1e2, 1e5, 1e8, 1e11}) {
    const ElmFit ridge = Fit(d.x, d.t, {.hidden_units = 60, .ridge_c = c});
    const double residual = (Predict(ridge.model, d.x) - d.t).cwiseAbs().maxCoeff();
    EXPECT_LT(residual, previous) << c;
    if (first == 0.0) first = residual;
    previous = residual;
  }
  // The smallest nonzero singular values of this H are tiny, so even C = 1e11 leaves a
  // visible residual; it has shrunk by orders of magnitude.
  EXPECT_LT(previous, 1e-2);
  EXPECT_LT(previous, 0.05 * first);
}

// The hidden layer recomputed by hand with std::exp, and the ridge solution from the normal
// equations solved by full-pivot LU and from the SVD: independent of the library's own code.
TEST(Elm, RidgeSolutionMatchesIndependentClosedForms) {
  const Data d = Smooth(12, 2, 2, 41);
  const int l = 5;
  const double c = 3.0;
  for (Solver solver : {Solver::kCholesky, Solver::kQr}) {
    const ElmFit fit = Fit(d.x, d.t, {.hidden_units = l, .ridge_c = c, .solver = solver});
    const ElmModel& m = fit.model;
    // Standardisation by training mean and population standard deviation.
    const Eigen::RowVectorXd x_mean = d.x.colwise().mean();
    const Eigen::RowVectorXd t_mean = d.t.colwise().mean();
    Eigen::MatrixXd xs = d.x.rowwise() - x_mean;
    Eigen::MatrixXd ts = d.t.rowwise() - t_mean;
    for (int j = 0; j < 2; ++j) {
      const double x_sd = std::sqrt(xs.col(j).squaredNorm() / 12.0);
      const double t_sd = std::sqrt(ts.col(j).squaredNorm() / 12.0);
      EXPECT_NEAR(m.input_scaler.scale[j], x_sd, 1e-14 * x_sd);
      EXPECT_NEAR(m.target_scaler.scale[j], t_sd, 1e-14 * t_sd);
      xs.col(j) /= x_sd;
      ts.col(j) /= t_sd;
    }
    Eigen::MatrixXd h(12, l);
    for (int i = 0; i < 12; ++i) {
      for (int j = 0; j < l; ++j) {
        const double z = xs.row(i).dot(m.input_weights.col(j)) + m.biases[j];
        h(i, j) = 1.0 / (1.0 + std::exp(-z));
      }
    }
    EXPECT_LT((HiddenLayer(m, d.x) - h).cwiseAbs().maxCoeff(), 1e-14);
    const Eigen::MatrixXd normal = h.transpose() * h + Eigen::MatrixXd::Identity(l, l) / c;
    const Eigen::MatrixXd beta_lu = normal.fullPivLu().solve(h.transpose() * ts);
    EXPECT_LT((m.output_weights - beta_lu).norm(), 1e-12 * beta_lu.norm()) << ToString(solver);
    // SVD form: beta = V diag(s / (s^2 + 1/C)) U^T T.
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(h, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::ArrayXd s = svd.singularValues().array();
    const Eigen::MatrixXd beta_svd = svd.matrixV() *
                                     (s / (s.square() + 1.0 / c)).matrix().asDiagonal() *
                                     svd.matrixU().transpose() * ts;
    EXPECT_LT((m.output_weights - beta_svd).norm(), 1e-12 * beta_svd.norm()) << ToString(solver);
    // Predictions map back to target units.
    const Eigen::MatrixXd y = (h * beta_lu).array().rowwise() * m.target_scaler.scale.array();
    EXPECT_LT((Predict(m, d.x) - (y.rowwise() + t_mean)).cwiseAbs().maxCoeff(), 1e-12);
    // Training RMSE (normal-equation identity for Cholesky, residual for QR).
    EXPECT_NEAR(fit.report.train_rmse, Rmse(Predict(m, d.x), d.t), 1e-9);
  }
  // C = inf with QR is the least-squares solution (full column rank here).
  const ElmFit ls = Fit(d.x, d.t,
                        {.hidden_units = l,
                         .ridge_c = std::numeric_limits<double>::infinity(),
                         .solver = Solver::kQr,
                         .standardize_inputs = false,
                         .standardize_targets = false});
  const Eigen::MatrixXd h = HiddenLayer(ls.model, d.x);
  const Eigen::MatrixXd beta_svd =
      h.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(d.t);
  EXPECT_LT((ls.model.output_weights - beta_svd).norm(), 1e-9 * beta_svd.norm());
}

// PRESS against brute force: refit without row i (same units, same fixed scaling), predict
// row i, for every (L, C) pair of a small grid, two outputs.
TEST(Elm, LeaveOneOutErrorsEqualBruteForceRefits) {
  const Data d = Smooth(40, 3, 2, 51);
  const std::vector<int> hidden_grid{3, 8, 15};
  const std::vector<double> ridge_grid{0.1, 10.0, 1000.0};
  const ElmOptions options{.hidden_units = 15,
                           .selection = Selection::kAuto,
                           .hidden_unit_candidates = hidden_grid,
                           .ridge_c_candidates = ridge_grid,
                           .standardize_inputs = false,
                           .standardize_targets = false,
                           .seed = 7};
  const ElmFit fit = Fit(d.x, d.t, options);
  ASSERT_EQ(fit.report.candidates.size(), 9u);
  // The same seed with L = 15 draws the same units; its hidden layer holds every prefix.
  ElmOptions full = options;
  full.selection = Selection::kFixed;
  const Eigen::MatrixXd h_full = HiddenLayer(Fit(d.x, d.t, full).model, d.x);
  const int n = 40;
  for (const LooCandidate& cand : fit.report.candidates) {
    ASSERT_FALSE(cand.skipped);
    const int l = cand.hidden_units;
    const Eigen::MatrixXd h = h_full.leftCols(l);
    double sse = 0.0;
    for (int i = 0; i < n; ++i) {
      Eigen::MatrixXd h_out(n - 1, l), t_out(n - 1, 2);
      h_out << h.topRows(i), h.bottomRows(n - 1 - i);
      t_out << d.t.topRows(i), d.t.bottomRows(n - 1 - i);
      const Eigen::MatrixXd normal =
          h_out.transpose() * h_out + Eigen::MatrixXd::Identity(l, l) / cand.ridge_c;
      const Eigen::MatrixXd beta = normal.fullPivLu().solve(h_out.transpose() * t_out);
      sse += (h.row(i) * beta - d.t.row(i)).squaredNorm();
    }
    const double mse = sse / (2.0 * n);
    EXPECT_NEAR(cand.loo_mse, mse, 1e-10 * mse) << "L=" << l << " C=" << cand.ridge_c;
    EXPECT_NEAR(cand.loo_rmse, std::sqrt(mse), 1e-10 * std::sqrt(mse));
  }
  // The model is the best pair, solved at that pair.
  const LooCandidate* best = &fit.report.candidates[0];
  for (const auto& c : fit.report.candidates) {
    if (c.loo_mse < best->loo_mse) best = &c;
  }
  EXPECT_EQ(fit.model.num_hidden(), best->hidden_units);
  EXPECT_EQ(fit.report.ridge_c, best->ridge_c);
  EXPECT_EQ(fit.model.options.hidden_units, best->hidden_units);
}

TEST(Elm, AutoSkipsIllConditionedPairs) {
  const Data d = Smooth(200, 2, 1, 52);
  const ElmFit fit = Fit(d.x, d.t,
                         {.hidden_units = 200,
                          .selection = Selection::kAuto,
                          .hidden_unit_candidates = {200},
                          .ridge_c_candidates = {1.0, 1e14}});
  ASSERT_EQ(fit.report.candidates.size(), 2u);
  EXPECT_FALSE(fit.report.candidates[0].skipped);
  EXPECT_TRUE(fit.report.candidates[1].skipped);
  EXPECT_GT(fit.report.candidates[1].condition, 1e12);
  EXPECT_EQ(fit.report.ridge_c, 1.0);
}

TEST(Elm, UnitsAreNestedAcrossNetworkSizes) {
  const Data d = Smooth(50, 3, 1, 61);
  const ElmModel small = Fit(d.x, d.t, {.hidden_units = 10}).model;
  const ElmModel large = Fit(d.x, d.t, {.hidden_units = 25}).model;
  EXPECT_TRUE(SameBits(small.input_weights, large.input_weights.leftCols(10)));
  EXPECT_TRUE(SameBits(small.biases, large.biases.head(10)));
  for (double w : large.input_weights.reshaped()) {
    EXPECT_GE(w, -1.0);
    EXPECT_LT(w, 1.0);
  }
  EXPECT_GE(large.biases.minCoeff(), 0.0);
  EXPECT_LT(large.biases.maxCoeff(), 1.0);
}

// A scaler fitted on the test rows (or refitted per Predict call) would change every
// prediction when the test distribution is shifted, and would give a different answer for a
// row predicted alone.
TEST(Elm, ScalerIsFittedOnTrainingRowsOnly) {
  const Data train = NoisySine(500, 0.05, 71);
  Data test = NoisySine(50, 0.05, 72);
  test.x.array() = test.x.array() * 0.3 + 2.0;  // shifted, narrower: different mean and std
  test.truth = test.x.array().sin().matrix();
  const ElmModel model = Fit(train.x, train.t, {.hidden_units = 20}).model;
  const double mean = train.x.mean();
  const double sd = std::sqrt((train.x.array() - mean).square().mean());
  EXPECT_DOUBLE_EQ(model.input_scaler.mean[0], mean);
  EXPECT_NEAR(model.input_scaler.scale[0], sd, 1e-14);
  EXPECT_DOUBLE_EQ(model.target_scaler.mean[0], train.t.mean());

  // A scaler fitted on the prediction rows would centre a lone row to 0 and change the answer
  // by O(1); the tolerance only allows for a vectorised versus scalar exp in the last bits.
  const Eigen::MatrixXd batch = Predict(model, test.x);
  for (int i = 0; i < 50; ++i) {
    EXPECT_NEAR(Predict(model, test.x.row(i))(0, 0), batch(i, 0), 1e-13) << i;
  }
  // And the batch equals the model applied by hand with the stored training scaler.
  const Eigen::MatrixXd xs = (test.x.array() - mean) / model.input_scaler.scale[0];
  const Eigen::MatrixXd z = (xs * model.input_weights).rowwise() + model.biases.transpose();
  const Eigen::MatrixXd h = (1.0 + (-z.array()).exp()).inverse().matrix();
  const Eigen::MatrixXd y = (h * model.output_weights).array() * model.target_scaler.scale[0] +
                            model.target_scaler.mean[0];
  EXPECT_LT((batch - y).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(Rmse(batch, test.truth), 0.05);
}

TEST(Elm, ConstantInputColumnIsOnlyCentred) {
  Data d = Smooth(80, 2, 1, 81);
  d.x.col(1).setConstant(4.25);
  const ElmFit fit = Fit(d.x, d.t, {.hidden_units = 15});
  EXPECT_EQ(fit.model.input_scaler.scale[1], 1.0);
  EXPECT_EQ(fit.model.input_scaler.mean[1], 4.25);
  EXPECT_TRUE(Predict(fit.model, d.x).allFinite());
}

TEST(Elm, SameSeedSameBitsDifferentSeedsDiffer) {
  const Data d = NoisySine(300, 0.1, 91);
  for (Activation a : {Activation::kSigmoid, Activation::kRbf}) {
    const ElmOptions options{.hidden_units = 20, .activation = a, .seed = 5};
    ElmOptions other = options;
    other.seed = 6;
    const ElmModel m1 = Fit(d.x, d.t, options).model;
    const ElmModel m2 = Fit(d.x, d.t, options).model;
    const ElmModel m3 = Fit(d.x, d.t, other).model;
    EXPECT_TRUE(SameBits(m1.input_weights, m2.input_weights));
    EXPECT_TRUE(SameBits(m1.output_weights, m2.output_weights));
    EXPECT_TRUE(SameBits(Predict(m1, d.x), Predict(m2, d.x)));
    EXPECT_FALSE(SameBits(m1.input_weights, m3.input_weights));
    EXPECT_GT((Predict(m1, d.x) - Predict(m3, d.x)).cwiseAbs().maxCoeff(), 1e-6);
  }
}

// 10000 rows span three row blocks, so two workers really split the work.
TEST(Elm, OneAndTwoThreadsGiveTheSameBits) {
  const Data d = NoisySine(10000, 0.1, 101);
  for (Selection selection : {Selection::kFixed, Selection::kAuto}) {
    for (Solver solver : {Solver::kCholesky, Solver::kQr}) {
      const ElmOptions o{.hidden_units = 40, .solver = solver, .selection = selection};
      const ElmFit f1 = Fit(d.x, d.t, o, {.threads = 1});
      const ElmFit f2 = Fit(d.x, d.t, o, {.threads = 2});
      EXPECT_EQ(f2.report.threads, 2);
      EXPECT_TRUE(SameBits(f1.model.output_weights, f2.model.output_weights))
          << ToString(selection) << " " << ToString(solver);
      ASSERT_EQ(f1.report.candidates.size(), f2.report.candidates.size());
      for (size_t k = 0; k < f1.report.candidates.size(); ++k) {
        const LooCandidate& a = f1.report.candidates[k];
        const LooCandidate& b = f2.report.candidates[k];
        EXPECT_EQ(a.skipped, b.skipped);
        if (!a.skipped) {
          EXPECT_EQ(std::memcmp(&a.loo_mse, &b.loo_mse, sizeof(double)), 0);
        }
      }
      EXPECT_EQ(f1.report.train_rmse, f2.report.train_rmse);
      EXPECT_TRUE(SameBits(Predict(f1.model, d.x, 1), Predict(f1.model, d.x, 2)));
      EXPECT_TRUE(SameBits(HiddenLayer(f1.model, d.x, 1), HiddenLayer(f1.model, d.x, 2)));
    }
  }
}

// The thread count is how a run executes (the Execution), not part of the model: a model fitted
// on 1 or 3 threads has the same options (so a saved model file is the same text).
TEST(Elm, ModelDoesNotRecordTheThreadCount) {
  const Data d = NoisySine(9000, 0.1, 105);
  for (Selection selection : {Selection::kFixed, Selection::kAuto}) {
    const ElmOptions o{.hidden_units = 20, .selection = selection};
    const ElmFit f1 = Fit(d.x, d.t, o, {.threads = 1});
    const ElmFit f3 = Fit(d.x, d.t, o, {.threads = 3});
    EXPECT_EQ(f1.model.options, f3.model.options);
    EXPECT_EQ(f3.report.threads, 3);  // the report says how the run executed
    EXPECT_TRUE(SameBits(f1.model.output_weights, f3.model.output_weights));
    EXPECT_EQ(f1.model.options.hidden_units, f3.model.options.hidden_units);
    EXPECT_EQ(f1.model.options.ridge_c, f3.model.options.ridge_c);
  }
  const ElmModel model = Fit(d.x, d.t, {.hidden_units = 5}).model;
  EXPECT_EQ(ErrorOf<UsageError>([&] { Predict(model, d.x, -1); }),
            "threads = -1: must be an integer in [0, 1024] (0 = all cores)");
  EXPECT_EQ(ErrorOf<UsageError>([&] { HiddenLayer(model, d.x, 1025); }),
            "threads = 1025: must be an integer in [0, 1024] (0 = all cores)");
  EXPECT_EQ(ErrorOf<UsageError>([&] { Fit(d.x, d.t, {}, {.threads = -1}); }),
            "threads = -1: must be an integer in [0, 1024] (0 = all cores)");
}

// A row predicted alone, in a short batch or inside a long one (across row blocks and at every
// position within the kernels' row tiles) is the same bits, for every activation and two outputs.
TEST(Elm, PredictsEachRowAloneToTheBitOfTheBatch) {
  const Data train = Smooth(600, 3, 2, 107);
  const Data test = Smooth(4096 + 45, 3, 2, 108);  // two row blocks, a ragged last tile
  for (Activation activation : {Activation::kSigmoid, Activation::kTanh, Activation::kSine,
                                Activation::kRbf, Activation::kLinear}) {
    // 23 units: not a multiple of the kernels' unit tile either.
    const ElmModel model =
        Fit(train.x, train.t, {.hidden_units = 23, .activation = activation}).model;
    const Eigen::MatrixXd all = Predict(model, test.x);
    const Eigen::MatrixXd h_all = HiddenLayer(model, test.x);
    for (Eigen::Index i : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 17, 4095, 4096, 4097, 4140}) {
      EXPECT_TRUE(SameBits(Predict(model, test.x.row(i)), all.row(i)))
          << ToString(activation) << " row " << i;
      EXPECT_TRUE(SameBits(HiddenLayer(model, test.x.row(i)), h_all.row(i)))
          << ToString(activation) << " row " << i;
    }
    for (Eigen::Index first : {0, 3, 4090}) {
      for (Eigen::Index count : {2, 5, 7, 13}) {
        EXPECT_TRUE(
            SameBits(Predict(model, test.x.middleRows(first, count)), all.middleRows(first, count)))
            << ToString(activation) << " rows " << first << " + " << count;
      }
    }
  }
}

TEST(Elm, MultiOutputFitsEachColumn) {
  const Data train = NoisySine(1000, 0.0, 111);
  Eigen::MatrixXd t(1000, 2);
  t.col(0) = train.x.col(0).array().sin();
  t.col(1) = 100.0 * train.x.col(0).array().cos() + 5.0;
  const ElmFit fit = Fit(train.x, t, {.hidden_units = 40});
  const Eigen::MatrixXd y = Predict(fit.model, train.x);
  EXPECT_EQ(y.cols(), 2);
  EXPECT_LT(Rmse(y.col(0), t.col(0)), 0.01);
  EXPECT_LT(Rmse(y.col(1), t.col(1)), 1.0);
}

TEST(Elm, BadOptionsAndDataThrowClearErrors) {
  const Data d = NoisySine(50, 0.1, 121);
  auto fit_with = [&](ElmOptions o) { return [&d, o] { Fit(d.x, d.t, o); }; };
  EXPECT_EQ(ErrorOf<UsageError>(fit_with({.hidden_units = 0})),
            "hidden_units = 0: must be an integer in [1, 10000]");
  EXPECT_EQ(ErrorOf<UsageError>(fit_with({.ridge_c = 0.0})),
            "ridge_c = 0: must be > 0 (inf = no regularisation, solver qr)");
  EXPECT_EQ(ErrorOf<UsageError>(fit_with({.ridge_c = -1.0})),
            "ridge_c = -1: must be > 0 (inf = no regularisation, solver qr)");
  EXPECT_NE(ErrorOf<UsageError>(fit_with({.ridge_c = std::nan("")})).find("ridge_c = nan"),
            std::string::npos);
  EXPECT_NE(ErrorOf<UsageError>(fit_with({.ridge_c = std::numeric_limits<double>::infinity()}))
                .find("solver = qr"),
            std::string::npos);
  EXPECT_NE(ErrorOf<UsageError>(fit_with({.hidden_units = 10,
                                          .selection = Selection::kAuto,
                                          .hidden_unit_candidates = {5, 11}}))
                .find("hidden_unit_candidates = 11"),
            std::string::npos);
  EXPECT_NE(ErrorOf<UsageError>(fit_with({.ridge_c_candidates = {1.0, -2.0}}))
                .find("ridge_c_candidates = -2"),
            std::string::npos);
  EXPECT_EQ(ErrorOf<UsageError>([] { ActivationFromString("relu"); }),
            "activation = 'relu': must be one of sigmoid, tanh, sine, rbf, linear");
  EXPECT_EQ(ActivationFromString(ToString(Activation::kRbf)), Activation::kRbf);
  EXPECT_EQ(SolverFromString("qr"), Solver::kQr);
  EXPECT_EQ(SelectionFromString("auto"), Selection::kAuto);

  Eigen::MatrixXd x_nan = d.x;
  x_nan(7, 0) = std::nan("");
  EXPECT_EQ(ErrorOf<DataError>([&] { Fit(x_nan, d.t, {}); }),
            "inputs row 8 column 1 is nan: every value must be finite");
  Eigen::MatrixXd t_inf = d.t;
  t_inf(3, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ErrorOf<DataError>([&] { Fit(d.x, t_inf, {}); }),
            "targets row 4 column 1 is inf: every value must be finite");
  EXPECT_EQ(ErrorOf<DataError>([&] { Fit(d.x, d.t.topRows(49), {}); }),
            "inputs have 50 rows but targets have 49: the row counts must match");
  EXPECT_EQ(ErrorOf<DataError>([&] { Fit(d.x.topRows(1), d.t.topRows(1), {}); }),
            "training data has 1 rows: at least 2 are needed");

  const ElmModel model = Fit(d.x, d.t, {.hidden_units = 5}).model;
  EXPECT_EQ(ErrorOf<DataError>([&] { Predict(model, Eigen::MatrixXd::Zero(3, 2)); }),
            "inputs have 2 columns but the ELM model has 1 inputs");
  EXPECT_NE(ErrorOf<DataError>([&] { Predict(model, x_nan); }).find("row 8"), std::string::npos);
  ElmModel broken = model;
  broken.biases.resize(4);
  EXPECT_EQ(ErrorOf<DataError>([&] { Predict(broken, d.x); }),
            "ELM model: 4 biases for 5 hidden units");
  broken = model;
  broken.target_scaler.scale[0] = 0.0;
  EXPECT_NE(ErrorOf<DataError>([&] { Predict(broken, d.x); }).find("scale"), std::string::npos);
}

TEST(Elm, DefaultGrids) {
  ElmOptions o{.hidden_units = 1000};
  EXPECT_EQ(o.HiddenUnitGrid(), (std::vector<int>{1, 2, 5, 10, 20, 50, 100, 200, 500, 1000}));
  o.hidden_units = 30;
  EXPECT_EQ(o.HiddenUnitGrid(), (std::vector<int>{1, 2, 5, 10, 20, 30}));
  const std::vector<double> c = o.RidgeGrid();
  ASSERT_EQ(c.size(), 13u);
  EXPECT_DOUBLE_EQ(c.front(), 1e-2);
  EXPECT_DOUBLE_EQ(c.back(), 1e10);
}

}  // namespace
}  // namespace gyrodrift::elm
