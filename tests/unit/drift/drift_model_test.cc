// The drift model's definition (drift_model.cc): the table of methods, modes and protocols, and
// GroupSeries, which turns a decomposition into the sub-series a model's sub-models take.
#include "gyrodrift/drift/drift_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gyrodrift/common/error.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

// Every name round-trips; thermal is the one compensate-only method, and the methods that
// decompose are the ones that identify a thermal model per group in compensate mode.
TEST(DriftModel, MethodTableNamesRoundTripAndThermalIsCompensateOnly) {
  const std::vector<Method> compensate = AllMethods(Mode::kCompensate);
  const std::vector<Method> predict = AllMethods(Mode::kPredict);
  EXPECT_EQ(compensate.size(), 7u);
  EXPECT_EQ(predict.size(), 11u);  // and the five filters of baseline.h
  EXPECT_EQ(std::find(predict.begin(), predict.end(), Method::kThermal), predict.end());
  for (Method m : compensate) {
    EXPECT_EQ(MethodFromString(ToString(m)), m) << ToString(m);
    EXPECT_EQ(SupportsMode(m, Mode::kPredict), m != Method::kThermal) << ToString(m);
    EXPECT_TRUE(SupportsMode(m, Mode::kCompensate)) << ToString(m);
    EXPECT_EQ(UsesDecomposition(m), m == Method::kMsElm || m == Method::kEmdElm) << ToString(m);
    DriftOptions o;
    o.method = m;
    o.mode = Mode::kCompensate;
    EXPECT_EQ(IdentifiesThermalModel(o), m == Method::kThermal || UsesDecomposition(m))
        << ToString(m);
    o.mode = Mode::kPredict;
    EXPECT_FALSE(IdentifiesThermalModel(o)) << ToString(m);
  }
  for (Mode m : {Mode::kPredict, Mode::kCompensate}) EXPECT_EQ(ModeFromString(ToString(m)), m);
  for (Protocol p : {Protocol::kPaper, Protocol::kCausal}) {
    EXPECT_EQ(ProtocolFromString(ToString(p)), p);
  }
  EXPECT_THROW(ProtocolFromString("future"), UsageError);
}

// Each sub-series sums its sub-model's IMFs; the sub-model with the residue also takes every IMF
// beyond the highest one listed (a new record may give more IMFs than the training record), and
// listed IMFs a shorter decomposition lacks add nothing. Powers of two: the sums are exact.
TEST(DriftModel, GroupSeriesGivesUnlistedImfsToTheResidueHolder) {
  DriftModel model;
  model.sub_models = {{"noise", {1, 2}, false, nullptr, nullptr},
                      {"drift", {3}, true, nullptr, nullptr}};
  decomposition::Decomposition d;
  d.imfs.resize(4, 5);
  for (int k = 0; k < 5; ++k) d.imfs.col(k).setConstant(std::ldexp(1.0, k));  // 1, 2, 4, 8, 16
  d.residue = Eigen::VectorXd::Constant(4, 32.0);
  Eigen::MatrixXd s = GroupSeries(model, d);
  ASSERT_EQ(s.rows(), 4);
  ASSERT_EQ(s.cols(), 2);
  EXPECT_EQ(Eigen::VectorXd(s.col(0)), Eigen::VectorXd::Constant(4, 1.0 + 2.0));
  EXPECT_EQ(Eigen::VectorXd(s.col(1)), Eigen::VectorXd::Constant(4, 4.0 + 8.0 + 16.0 + 32.0));
  d.imfs = Eigen::MatrixXd(d.imfs.leftCols(2));
  s = GroupSeries(model, d);
  EXPECT_EQ(Eigen::VectorXd(s.col(0)), Eigen::VectorXd::Constant(4, 1.0 + 2.0));
  EXPECT_EQ(Eigen::VectorXd(s.col(1)), Eigen::VectorXd::Constant(4, 32.0));
}

TEST(DriftModel, MsElmPredictModeBuildsGroupsThatSumToTheSignal) {
  const Log log = MakeLog(1500, 1);
  const DriftModel model =
      FitDriftModel(log.rate, Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  ASSERT_GE(model.sub_models.size(), 2u) << model.Summary();
  EXPECT_EQ(model.lags, 4);
  EXPECT_GT(model.training_imfs, 3);
  decomposition::DecompositionOptions d = model.options.decomposition;
  d.seed = model.options.seed;
  const Eigen::MatrixXd series = GroupSeries(model, decomposition::Decompose(log.rate, d));
  EXPECT_LE((series.rowwise().sum() - log.rate).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace gyrodrift::drift
