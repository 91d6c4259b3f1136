// The learner interface (learner.cc) over every kind: each learns a smooth 2-D function far
// better than the mean, Save/Load round trips give the same bits, scalers come from the training
// rows only, rows predict alike alone and in a batch, kind names round-trip, concurrent fits
// equal sequential ones, and bad options, data and parameters are rejected with the right error
// kind. What defines one kind is tested in learner_<kind>_test.cc.
#include "gyrodrift/drift/learner.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "unit/drift/learner_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Data;
using fixtures::OptionsOf;
using fixtures::Rmse;
using fixtures::SameBits;
using fixtures::SineBowl;

const std::vector<LearnerKind> kAllKinds{LearnerKind::kElm, LearnerKind::kPoly, LearnerKind::kSvr,
                                         LearnerKind::kBp};

class EveryKind : public ::testing::TestWithParam<LearnerKind> {};

TEST_P(EveryKind, LearnsSineBowlFarBetterThanTheMean) {
  const Data train = SineBowl(600, 0.05, 1);
  const Data test = SineBowl(400, 0.0, 2);
  const auto learner = FitLearner(train.x, train.y, OptionsOf(GetParam()));
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
  const auto learner = FitLearner(train.x, train.y, OptionsOf(GetParam()));
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
  const auto learner = FitLearner(train.x, train.y, OptionsOf(GetParam()));
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
  const Parameters saved = FitLearner(train.x, train.y, OptionsOf(GetParam()))->Save();
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
  const LearnerOptions o = OptionsOf(GetParam());
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
  const auto learner = FitLearner(train.x, train.y, OptionsOf(GetParam()));
  const Eigen::VectorXd all = learner->Predict(test.x);
  for (Eigen::Index i = 0; i < test.x.rows(); i += 7) {
    // Every kind, ELM included (its row kernels fix the summation order, docs/elm.md), gives
    // a row alone the same bits as inside a batch.
    EXPECT_EQ(learner->Predict(test.x.row(i))[0], all[i]) << "row " << i;
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

// libsvm training is serialised internally and FANN networks share no state: fits running on
// two threads give the same bits as fits run one after the other.
TEST(Learner, ConcurrentFitsMatchSequentialFits) {
  const Data train = SineBowl(200, 0.05, 20);
  const Data test = SineBowl(50, 0.0, 21);
  const std::vector<LearnerKind> kinds{LearnerKind::kSvr, LearnerKind::kBp,   LearnerKind::kSvr,
                                       LearnerKind::kBp,  LearnerKind::kPoly, LearnerKind::kElm};
  auto fit = [&](int task) {
    LearnerOptions o = OptionsOf(kinds[static_cast<size_t>(task)]);
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
