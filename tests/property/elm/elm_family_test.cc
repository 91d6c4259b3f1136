// One property tester run over every activation, with and without standardisation: the PRESS
// errors equal brute-force refits, the Cholesky and QR solvers agree, the reported training
// RMSE is the RMSE of the predictions, and the thread count does not change a bit.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>

#include "gyrodrift/common/random.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::elm {
namespace {

struct Problem {
  Eigen::MatrixXd x, t;
};

Problem MakeProblem(int n, std::uint64_t seed) {
  Rng rng(seed, 0);
  Problem p;
  p.x.resize(n, 3);
  p.t.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < 3; ++j) p.x(i, j) = 10.0 * j + rng.Uniform(-1.0, 1.0) * (j + 1);
    p.t(i, 0) = 50.0 + 20.0 * std::tanh(p.x(i, 0)) + std::sin(p.x(i, 2)) + 0.1 * rng.Normal();
  }
  return p;
}

class ElmFamily : public ::testing::TestWithParam<std::tuple<Activation, bool>> {
 protected:
  ElmOptions Options() const {
    ElmOptions o;
    o.activation = std::get<0>(GetParam());
    o.standardize_inputs = std::get<1>(GetParam());
    o.standardize_targets = std::get<1>(GetParam());
    o.seed = 3;
    return o;
  }
};

TEST_P(ElmFamily, PressEqualsBruteForceLeaveOneOut) {
  const Problem p = MakeProblem(25, 1);
  ElmOptions o = Options();
  o.hidden_units = 12;
  o.selection = Selection::kAuto;
  o.hidden_unit_candidates = {4, 12};
  o.ridge_c_candidates = {0.5, 50.0};
  const ElmFit fit = Fit(p.x, p.t, o);
  ElmOptions full = o;
  full.selection = Selection::kFixed;
  const ElmModel full_model = Fit(p.x, p.t, full).model;
  const Eigen::MatrixXd h_all = HiddenLayer(full_model, p.x);
  const Eigen::MatrixXd ts = full_model.target_scaler.Apply(p.t);
  const int n = 25;
  for (const LooCandidate& c : fit.report.candidates) {
    ASSERT_FALSE(c.skipped);
    const int l = c.hidden_units;
    double sse = 0.0;
    for (int i = 0; i < n; ++i) {
      Eigen::MatrixXd h(n - 1, l), t(n - 1, 1);
      h << h_all.topLeftCorner(i, l), h_all.bottomLeftCorner(n - 1 - i, l);
      t << ts.topRows(i), ts.bottomRows(n - 1 - i);
      const Eigen::MatrixXd a = h.transpose() * h + Eigen::MatrixXd::Identity(l, l) / c.ridge_c;
      const Eigen::MatrixXd beta = a.fullPivLu().solve(h.transpose() * t);
      sse += (h_all.row(i).head(l) * beta - ts.row(i)).squaredNorm();
    }
    EXPECT_NEAR(c.loo_mse, sse / n, 1e-10 * sse / n) << "L=" << l << " C=" << c.ridge_c;
    const double scale = full_model.target_scaler.scale[0];
    EXPECT_NEAR(c.loo_rmse, std::sqrt(sse / n) * scale, 1e-10 * std::sqrt(sse / n) * scale);
  }
}

TEST_P(ElmFamily, CholeskyAndQrAgreeAndTrainRmseIsThePredictionRmse) {
  const Problem p = MakeProblem(300, 2);
  ElmOptions o = Options();
  o.hidden_units = 15;
  o.ridge_c = 100.0;
  ElmOptions qr = o;
  qr.solver = Solver::kQr;
  const ElmFit a = Fit(p.x, p.t, o);
  const ElmFit b = Fit(p.x, p.t, qr);
  EXPECT_LT((a.model.output_weights - b.model.output_weights).norm(),
            1e-8 * b.model.output_weights.norm());
  for (const ElmFit* f : {&a, &b}) {
    const Eigen::MatrixXd y = Predict(f->model, p.x);
    const double rmse = std::sqrt((y - p.t).squaredNorm() / 300.0);
    EXPECT_NEAR(f->report.train_rmse, rmse, 1e-7 * rmse) << ToString(f->report.solver);
  }
}

TEST_P(ElmFamily, ThreadCountDoesNotChangeBits) {
  const Problem p = MakeProblem(9000, 3);  // three row blocks
  ElmOptions o = Options();
  o.hidden_units = 30;
  o.selection = Selection::kAuto;
  const ElmFit a = Fit(p.x, p.t, o, {.threads = 1});
  const ElmFit b = Fit(p.x, p.t, o, {.threads = 3});
  ASSERT_EQ(a.model.output_weights.size(), b.model.output_weights.size());
  EXPECT_EQ(std::memcmp(a.model.output_weights.data(), b.model.output_weights.data(),
                        sizeof(double) * a.model.output_weights.size()),
            0);
  const Eigen::MatrixXd ya = Predict(a.model, p.x, 1), yb = Predict(a.model, p.x, 3);
  EXPECT_EQ(std::memcmp(ya.data(), yb.data(), sizeof(double) * ya.size()), 0);
}

INSTANTIATE_TEST_SUITE_P(
    AllActivations, ElmFamily,
    ::testing::Combine(::testing::Values(Activation::kSigmoid, Activation::kTanh,
                                         Activation::kSine, Activation::kRbf,
                                         Activation::kLinear),
                       ::testing::Bool()),
    [](const auto& info) {
      return std::string(ToString(std::get<0>(info.param))) +
             (std::get<1>(info.param) ? "_standardised" : "_raw");
    });

}  // namespace
}  // namespace gyrodrift::elm
