// Learners: each kind learns a smooth 2-D function far better than the mean, the polynomial
// recovers an exact polynomial, Save/Load round trips give the same bits, seeds reproduce and
// differ, scalers come from the training rows only, and bad options, data and parameters are
// rejected with the right error kind.
#include "gyrodrift/drift/learner.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::drift {
namespace {

struct Data {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;      // noisy
  Eigen::VectorXd truth;  // noise-free
};

// y = sin(x1) + 0.5 x2^2 + noise, x uniform on [-2, 2]^2.
Data SineBowl(int n, double noise_sd, std::uint64_t seed) {
  Rng rng(seed, 0);
  Data d;
  d.x.resize(n, 2);
  d.y.resize(n);
  d.truth.resize(n);
  for (int i = 0; i < n; ++i) {
    d.x(i, 0) = rng.Uniform(-2.0, 2.0);
    d.x(i, 1) = rng.Uniform(-2.0, 2.0);
    d.truth[i] = std::sin(d.x(i, 0)) + 0.5 * d.x(i, 1) * d.x(i, 1);
    d.y[i] = d.truth[i] + noise_sd * rng.Normal();
  }
  return d;
}

double Rmse(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

LearnerOptions Options(LearnerKind kind) {
  LearnerOptions o;
  o.kind = kind;
  o.poly_degree = 3;
  return o;
}

const std::vector<LearnerKind> kAllKinds{LearnerKind::kElm, LearnerKind::kPoly, LearnerKind::kSvr,
                                         LearnerKind::kBp};

class EveryKind : public ::testing::TestWithParam<LearnerKind> {};

TEST_P(EveryKind, LearnsSineBowlFarBetterThanTheMean) {
  const Data train = SineBowl(600, 0.05, 1);
  const Data test = SineBowl(400, 0.0, 2);
  const auto learner = FitLearner(train.x, train.y, Options(GetParam()));
  EXPECT_EQ(learner->kind(), GetParam());
  EXPECT_EQ(learner->num_inputs(), 2);
  const Eigen::VectorXd p = learner->Predict(test.x);
  const double mean_rmse =
      Rmse(Eigen::VectorXd::Constant(test.truth.size(), train.y.mean()), test.truth);
  const double rmse = Rmse(p, test.truth);
  // The mean predictor's RMSE is about 1; every learner should be within a tenth of it.
  EXPECT_LT(rmse, 0.1 * mean_rmse) << learner->Summary();
  std::printf("%s; test RMSE %.4f (mean predictor %.4f)\n", learner->Summary().c_str(), rmse,
              mean_rmse);
  const std::string summary = learner->Summary();
  EXPECT_EQ(summary.find('\n'), std::string::npos);
  EXPECT_EQ(summary.rfind(std::string(ToString(GetParam())) + ":", 0), 0u) << summary;
  EXPECT_NE(summary.find("train RMSE"), std::string::npos) << summary;
}

TEST_P(EveryKind, SaveLoadRoundTripGivesIdenticalBits) {
  const Data train = SineBowl(300, 0.05, 3);
  const Data test = SineBowl(200, 0.0, 4);
  const auto learner = FitLearner(train.x, train.y, Options(GetParam()));
  const Parameters saved = learner->Save();
  const auto loaded = LoadLearner(GetParam(), saved);
  EXPECT_EQ(loaded->kind(), GetParam());
  EXPECT_EQ(loaded->num_inputs(), 2);
  EXPECT_TRUE(SameBits(learner->Predict(test.x), loaded->Predict(test.x)));
  EXPECT_TRUE(SameBits(learner->Predict(train.x), loaded->Predict(train.x)));
  EXPECT_EQ(learner->Summary(), loaded->Summary());
  // How many threads fitted it is not a parameter; those saved before model format 6 kept it (ELM,
  // SVR), and still load.
  EXPECT_EQ(saved.scalars.count("threads"), 0u);
  Parameters legacy = saved;
  legacy.scalars["threads"] = 2;
  EXPECT_TRUE(SameBits(learner->Predict(test.x), LoadLearner(GetParam(), legacy)->Predict(test.x)));
  // Saving the loaded learner gives the same parameters again.
  const Parameters again = loaded->Save();
  EXPECT_EQ(again.texts, saved.texts);
  EXPECT_EQ(again.scalars, saved.scalars);
  ASSERT_EQ(again.arrays.size(), saved.arrays.size());
  for (const auto& [name, a] : saved.arrays) {
    ASSERT_TRUE(again.arrays.count(name)) << name;
    EXPECT_TRUE(a.rows() == again.arrays.at(name).rows() && a == again.arrays.at(name)) << name;
  }
}

TEST_P(EveryKind, ScalersComeFromTheTrainingRowsOnly) {
  Data train = SineBowl(200, 0.05, 5);
  train.x.col(0).array() += 7.0;  // an offset the scaler must see
  const auto learner = FitLearner(train.x, train.y, Options(GetParam()));
  const Parameters p = learner->Save();
  ASSERT_TRUE(p.arrays.count("input_mean") && p.arrays.count("target_mean"));
  const Eigen::RowVectorXd mean = train.x.colwise().mean();
  EXPECT_NEAR((p.arrays.at("input_mean") - Eigen::MatrixXd(mean)).cwiseAbs().maxCoeff(), 0.0,
              1e-12);
  EXPECT_NEAR(p.arrays.at("target_mean")(0, 0), train.y.mean(), 1e-12);
  const double sd0 = std::sqrt((train.x.col(0).array() - mean[0]).square().mean());
  EXPECT_NEAR(p.arrays.at("input_scale")(0, 0), sd0, 1e-12);
  // Predicting on other rows does not move the scaler.
  const Data other = SineBowl(50, 0.0, 6);
  (void)learner->Predict(other.x);
  EXPECT_EQ(learner->Save().arrays.at("input_mean"), p.arrays.at("input_mean"));
}

TEST_P(EveryKind, LoadRejectsMissingOrMisShapedArrays) {
  const Data train = SineBowl(120, 0.05, 7);
  const Parameters saved = FitLearner(train.x, train.y, Options(GetParam()))->Save();
  for (const auto& [name, a] : saved.arrays) {
    Parameters missing = saved;
    missing.arrays.erase(name);
    EXPECT_THROW(LoadLearner(GetParam(), missing), DataError) << "missing " << name;
    Parameters wide = saved;
    wide.arrays[name].conservativeResize(a.rows(), a.cols() + 1);
    wide.arrays[name].col(a.cols()).setOnes();
    EXPECT_THROW(LoadLearner(GetParam(), wide), DataError) << "wide " << name;
    Parameters tall = saved;
    tall.arrays[name].conservativeResize(a.rows() + 1, a.cols());
    tall.arrays[name].row(a.rows()).setOnes();
    EXPECT_THROW(LoadLearner(GetParam(), tall), DataError) << "tall " << name;
    if (a.size() > 0) {
      Parameters nan = saved;
      nan.arrays[name](0, 0) = std::numeric_limits<double>::quiet_NaN();
      EXPECT_THROW(LoadLearner(GetParam(), nan), DataError) << "NaN in " << name;
    }
  }
  for (const auto& [name, v] : saved.scalars) {
    Parameters missing = saved;
    missing.scalars.erase(name);
    EXPECT_THROW(LoadLearner(GetParam(), missing), DataError) << "missing scalar " << name;
  }
  Parameters no_kind = saved;
  no_kind.texts.erase("kind");
  EXPECT_THROW(LoadLearner(GetParam(), no_kind), DataError);
  for (LearnerKind other : kAllKinds) {
    if (other != GetParam()) {
      EXPECT_THROW(LoadLearner(other, saved), DataError);
    }
  }
  Parameters bad_seed = saved;
  bad_seed.texts["seed"] = "12x";
  EXPECT_THROW(LoadLearner(GetParam(), bad_seed), DataError);
}

TEST_P(EveryKind, RejectsBadTrainingAndPredictionData) {
  const Data train = SineBowl(50, 0.05, 8);
  const LearnerOptions o = Options(GetParam());
  EXPECT_THROW(FitLearner(train.x, train.y.head(49), o), DataError);
  EXPECT_THROW(FitLearner(train.x.topRows(1), train.y.head(1), o), DataError);
  Eigen::MatrixXd x = train.x;
  x(2, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    FitLearner(x, train.y, o);
    ADD_FAILURE() << "NaN input accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("row 3"), std::string::npos) << e.what();
  }
  Eigen::VectorXd y = train.y;
  y[4] = std::numeric_limits<double>::infinity();
  try {
    FitLearner(train.x, y, o);
    ADD_FAILURE() << "infinite target accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("row 5"), std::string::npos) << e.what();
  }
  const auto learner = FitLearner(train.x, train.y, o);
  EXPECT_THROW(learner->Predict(Eigen::MatrixXd::Zero(3, 3)), DataError);
  EXPECT_THROW(learner->Predict(x), DataError);
  EXPECT_EQ(learner->Predict(Eigen::MatrixXd::Zero(0, 2)).size(), 0);
}

TEST_P(EveryKind, PredictsEachRowIndependentlyOfTheBatch) {
  const Data train = SineBowl(150, 0.05, 9);
  const Data test = SineBowl(40, 0.0, 10);
  const auto learner = FitLearner(train.x, train.y, Options(GetParam()));
  const Eigen::VectorXd all = learner->Predict(test.x);
  for (Eigen::Index i = 0; i < test.x.rows(); i += 7) {
    const Eigen::VectorXd one = learner->Predict(test.x.row(i));
    if (GetParam() == LearnerKind::kElm) {
      // elm::Predict multiplies row blocks with Eigen's matrix products, whose summation
      // order depends on the block's row count: the last bit may differ.
      EXPECT_NEAR(one[0], all[i], 1e-14 * (1.0 + std::abs(all[i]))) << "row " << i;
    } else {
      EXPECT_EQ(one[0], all[i]) << "row " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Learner, EveryKind, ::testing::ValuesIn(kAllKinds),
                         [](const ::testing::TestParamInfo<LearnerKind>& info) {
                           return std::string(ToString(info.param));
                         });

TEST(Learner, KindNamesRoundTrip) {
  for (LearnerKind kind : kAllKinds) EXPECT_EQ(LearnerKindFromString(ToString(kind)), kind);
  EXPECT_THROW(LearnerKindFromString("rf"), UsageError);
}

TEST(Learner, SeedReproducesAndDifferentSeedsDiffer) {
  const Data train = SineBowl(200, 0.05, 11);
  const Data test = SineBowl(100, 0.0, 12);
  for (LearnerKind kind : {LearnerKind::kElm, LearnerKind::kBp}) {
    LearnerOptions o = Options(kind);
    o.seed = 5;
    const Eigen::VectorXd a = FitLearner(train.x, train.y, o, {.threads = 2})->Predict(test.x);
    // The thread count must not matter.
    const Eigen::VectorXd b = FitLearner(train.x, train.y, o, {.threads = 1})->Predict(test.x);
    o.seed = 6;
    const Eigen::VectorXd c = FitLearner(train.x, train.y, o)->Predict(test.x);
    EXPECT_TRUE(SameBits(a, b)) << ToString(kind);
    EXPECT_GT((a - c).cwiseAbs().maxCoeff(), 1e-9) << ToString(kind);
  }
}

TEST(Learner, ElmUsesTheLearnerSeedAndAutoSelection) {
  const Data train = SineBowl(300, 0.05, 13);
  LearnerOptions o = Options(LearnerKind::kElm);
  o.seed = 21;
  o.elm.seed = 99;  // overridden by o.seed
  o.elm.hidden_units = 50;
  o.elm.selection = elm::Selection::kAuto;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  EXPECT_EQ(p.texts.at("seed"), "21");
  EXPECT_EQ(p.texts.at("selection"), "auto");
  EXPECT_LE(p.scalars.at("hidden_units"), 50.0);
  EXPECT_NE(learner->Summary().find("auto"), std::string::npos);
  const Data test = SineBowl(100, 0.0, 14);
  EXPECT_LT(Rmse(learner->Predict(test.x), test.truth), 0.1);
}

TEST(Learner, PolyRecoversAnExactPolynomial) {
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
    LearnerOptions o = Options(LearnerKind::kPoly);
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
  LearnerOptions o1 = Options(LearnerKind::kPoly);
  o1.poly_degree = 1;
  EXPECT_GT(FitLearner(x, y, o1)->Save().scalars.at("train_rmse"), 0.1);
}

TEST(Learner, PolyRejectsTooManyTerms) {
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(40, 30);
  const Eigen::VectorXd y = Eigen::VectorXd::Random(40);
  LearnerOptions o = Options(LearnerKind::kPoly);
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

// The SVR expansion evaluated here is libsvm's decision function: at a free support vector
// (0 < |coef| < C) the KKT conditions put the residual exactly on the epsilon tube.
TEST(Learner, SvrFreeSupportVectorsSitOnTheEpsilonTube) {
  const Data train = SineBowl(300, 0.1, 16);
  LearnerOptions o = Options(LearnerKind::kSvr);
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

TEST(Learner, SvrTrainsOnAnEvenlySpacedSubsample) {
  const Data train = SineBowl(500, 0.05, 17);
  LearnerOptions o = Options(LearnerKind::kSvr);
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

TEST(Learner, SvrConstantTargetHasNoSupportVectorsAndRoundTrips) {
  const Data train = SineBowl(40, 0.0, 18);
  const Eigen::VectorXd y = Eigen::VectorXd::Constant(40, 3.25);
  const auto learner = FitLearner(train.x, y, Options(LearnerKind::kSvr));
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

TEST(Learner, BpStopsAtTheDesiredMseOrTheEpochCap) {
  const Data train = SineBowl(200, 0.05, 19);
  LearnerOptions o = Options(LearnerKind::kBp);
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

// libsvm training is serialised internally and FANN networks share no state: fits running on
// two threads give the same bits as fits run one after the other.
TEST(Learner, ConcurrentFitsMatchSequentialFits) {
  const Data train = SineBowl(200, 0.05, 20);
  const Data test = SineBowl(50, 0.0, 21);
  const std::vector<LearnerKind> kinds{LearnerKind::kSvr, LearnerKind::kBp,   LearnerKind::kSvr,
                                       LearnerKind::kBp,  LearnerKind::kPoly, LearnerKind::kElm};
  auto fit = [&](int task) {
    LearnerOptions o = Options(kinds[static_cast<size_t>(task)]);
    o.seed = static_cast<std::uint64_t>(task);
    o.bp_epochs = 100;
    return FitLearner(train.x, train.y, o, {.threads = 1})->Predict(test.x);
  };
  const int n = static_cast<int>(kinds.size());
  std::vector<Eigen::VectorXd> sequential(kinds.size());
  std::vector<Eigen::VectorXd> concurrent(kinds.size());
  for (int task = 0; task < n; ++task) sequential[static_cast<size_t>(task)] = fit(task);
  ParallelFor(n, 2, [&](int task, int) { concurrent[static_cast<size_t>(task)] = fit(task); });
  for (int task = 0; task < n; ++task) {
    EXPECT_TRUE(
        SameBits(sequential[static_cast<size_t>(task)], concurrent[static_cast<size_t>(task)]))
        << "task " << task;
  }
}

TEST(Learner, ValidateRejectsBadOptions) {
  struct Case {
    std::function<void(LearnerOptions&)> mutate;
    std::string field;
  };
  const std::vector<Case> cases{
      {[](LearnerOptions& o) { o.poly_degree = 0; }, "poly_degree"},
      {[](LearnerOptions& o) { o.poly_degree = 5; }, "poly_degree"},
      {[](LearnerOptions& o) { o.poly_ridge = -1e-3; }, "poly_ridge"},
      {[](LearnerOptions& o) { o.poly_ridge = std::nan(""); }, "poly_ridge"},
      {[](LearnerOptions& o) { o.svr_c = 0.0; }, "svr_c"},
      {[](LearnerOptions& o) { o.svr_c = std::numeric_limits<double>::infinity(); }, "svr_c"},
      {[](LearnerOptions& o) { o.svr_epsilon = -0.1; }, "svr_epsilon"},
      {[](LearnerOptions& o) { o.svr_gamma = -1.0; }, "svr_gamma"},
      {[](LearnerOptions& o) { o.svr_max_rows = 1; }, "svr_max_rows"},
      {[](LearnerOptions& o) { o.bp_hidden = {}; }, "bp_hidden"},
      {[](LearnerOptions& o) {
         o.bp_hidden = {4, 4, 4, 4};
       },
       "bp_hidden"},
      {[](LearnerOptions& o) {
         o.bp_hidden = {10, 0};
       },
       "bp_hidden"},
      {[](LearnerOptions& o) { o.bp_hidden = {1001}; }, "bp_hidden"},
      {[](LearnerOptions& o) { o.bp_epochs = 0; }, "bp_epochs"},
      {[](LearnerOptions& o) { o.bp_epochs = 100001; }, "bp_epochs"},
      {[](LearnerOptions& o) { o.bp_desired_mse = -1.0; }, "bp_desired_mse"},
      {[](LearnerOptions& o) { o.elm.hidden_units = 0; }, "elm.hidden_units"},
      {[](LearnerOptions& o) { o.elm.ridge_c = -1.0; }, "elm.ridge_c"},
  };
  LearnerOptions ok;
  EXPECT_NO_THROW(ok.Validate());
  for (const Case& c : cases) {
    LearnerOptions o;
    c.mutate(o);
    try {
      o.Validate();
      ADD_FAILURE() << c.field << " accepted";
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(c.field + " = ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("must be"), std::string::npos) << e.what();
    }
    // FitLearner validates too.
    o.kind = LearnerKind::kPoly;
    EXPECT_THROW(FitLearner(Eigen::MatrixXd::Ones(4, 1), Eigen::VectorXd::Ones(4), o), UsageError)
        << c.field;
  }
  // And the execution's thread count.
  EXPECT_THROW(FitLearner(Eigen::MatrixXd::Ones(4, 1), Eigen::VectorXd::Ones(4), LearnerOptions{},
                          {.threads = -1}),
               UsageError);
}

}  // namespace
}  // namespace gyrodrift::drift
