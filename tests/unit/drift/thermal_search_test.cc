// The one-standard-error rule of the thermal identification on hand-made fold scores
// (drift/thermal_search.h, ChooseLevel; docs/drift.md 4.8).
#include "drift/thermal_search.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <vector>

namespace gyrodrift::drift::internal {
namespace {

// Eight equal time blocks of a 64-row run: ChooseLevel reads only their weights (Mean and
// StandardError), so the design is a column of ones and the target zero.
struct EightFolds {
  Eigen::MatrixXd x = Eigen::MatrixXd::Ones(64, 1);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(64);
  Eigen::VectorXd weight = Eigen::VectorXd::Ones(64);
  std::vector<FoldRows> rows;
  EightFolds() {
    for (Eigen::Index k = 0; k < 8; ++k) rows.push_back({kTimeBlocks, {{8 * k, 8 * k + 8}}});
  }
};

// best[level] = the level's best subset with these fold scores (its level named once).
void Put(LevelBests& best, int level, std::initializer_list<double> per_fold) {
  Subset& s = best[static_cast<size_t>(level)];
  s = Subset{};
  s.level = level;
  s.fold_scores = Eigen::Map<const Eigen::VectorXd>(per_fold.begin(),
                                                    static_cast<Eigen::Index>(per_fold.size()));
  s.score = s.fold_scores.mean();
}

SearchResult Choose(const LevelBests& best) {
  const EightFolds f;
  const FoldScores scores(f.x, f.y, f.weight, f.rows);
  SearchResult result;
  result.constant = best[CalibrationReport::kConstant];
  ChooseLevel(scores, SearchRules{}, best, result);
  return result;
}

// The steady support holds a steady-state drift within the band the run's block means spanned,
// widened by its width on either side, and nothing beyond (nor a fit that is not finite).
TEST(SteadySupport, HoldsACurveWithinTheBandWidenedByItsWidth) {
  SteadySupport support;
  support.design.resize(3, 3);
  support.design << 1.0, -1.0, 1.0,  // the intercept, z, z^2 at z = -1, 0, 1
      1.0, 0.0, 0.0,                 //
      1.0, 1.0, 1.0;
  support.low = -1.0;
  support.high = 1.0;  // allowed: [-3, 3]
  const std::vector<int> line{0, 1}, parabola{0, 2};
  EXPECT_TRUE(support.Holds(Eigen::Vector2d(0.0, 3.0), line));
  EXPECT_FALSE(support.Holds(Eigen::Vector2d(0.0, 3.5), line));
  EXPECT_TRUE(support.Holds(Eigen::Vector2d(-2.0, 5.0), parabola));  // -2 .. 3
  EXPECT_FALSE(support.Holds(Eigen::Vector2d(-3.5, 5.0), parabola));
  EXPECT_FALSE(support.Holds(Eigen::Vector2d(0.0, std::numeric_limits<double>::quiet_NaN()), line));
}

// SteadySupportOf: the grid runs from the channel's lowest to its highest temperature (61
// points), each static and state column its power of the standardised level there (the rate 0),
// and the band spans the means of whole blocks over their logged samples (the last partial block
// does not count).
TEST(SteadySupport, OfARunIsItsGridAndTheBandOfItsBlockMeans) {
  const Eigen::Index n = 105, block = 10;
  Eigen::VectorXd t(n), yc(n), weight = Eigen::VectorXd::Ones(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    t[i] = 40.0 * static_cast<double>(i) / 99.0;         // 0..40 degC over the whole blocks
    yc[i] = static_cast<double>(i / block) * 0.1 - 0.3;  // block means -0.3 .. 0.6
  }
  t.tail(5).setConstant(20.0);  // the last partial block: inside the range, its mean ignored
  yc.tail(5).setConstant(9.0);
  weight[5] = 0.0;  // a made-up row in block 0: its mean is the others' (-0.27 over all 10)
  yc[5] = 0.0;      // (yc is 0 where not logged)
  ThermalRegression model;
  model.centre_c = {20.0};
  model.scale_k = {10.0};
  model.static_min = {-2.0};
  model.static_max = {2.0};
  ThermalState state;
  state.level_min = -2.0;
  state.level_max = 2.0;
  const DesignLayout layout{1, 3, 1, 4, 0};
  const SteadySupport s = SteadySupportOf(t, yc, weight, block, model, layout, {state});
  ASSERT_EQ(s.design.rows(), 61);
  ASSERT_EQ(s.design.cols(), 1 + 3 + 4);
  for (Eigen::Index g : {Eigen::Index{0}, Eigen::Index{30}, Eigen::Index{60}}) {
    const double z = -2.0 + 4.0 * static_cast<double>(g) / 60.0;
    EXPECT_DOUBLE_EQ(s.design(g, 0), 1.0);
    for (int p = 1; p <= 3; ++p) {
      EXPECT_NEAR(s.design(g, layout.StaticColumn(0, p)), std::pow(z, p), 1e-12) << g << " " << p;
      EXPECT_NEAR(s.design(g, layout.StateColumn(0, p - 1)), std::pow(z, p), 1e-12) << g;
    }
    EXPECT_EQ(s.design(g, layout.StateColumn(0, 3)), 0.0);  // the rate
  }
  EXPECT_DOUBLE_EQ(s.low, -0.3);
  EXPECT_NEAR(s.high, 0.6, 1e-12);
}

// Unit 54 of the family's 16-h calibrations, in miniature: one state with its rate comes within a
// standard error of the best (two states) but has one bad fold, so it does not beat the constant;
// the two states beat the constant on every fold. The choice passes to the two states (before:
// the constant, which cost that unit 13 points of the mission's drift).
TEST(ThermalSearch, ALevelThatDoesNotBeatTheConstantPassesTheChoiceOn) {
  LevelBests best;
  Put(best, CalibrationReport::kConstant, {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0});
  Put(best, CalibrationReport::kOneState, {0.9, 0.9, 0.9, 8.0, 0.9, 0.9, 0.9, 0.9});
  Put(best, CalibrationReport::kTwoStates, {0.95, 0.94, 0.96, 0.95, 0.93, 0.96, 0.95, 0.94});
  // Static powers and the lagged level clearly worse than the best, hysteresis not scored; one
  // state's mean is the best's + 0.84 with a standard error of 0.89 (one fold): within reach.
  Put(best, CalibrationReport::kStatic, {0.99, 0.99, 0.99, 0.99, 0.99, 0.99, 0.99, 0.99});
  Put(best, CalibrationReport::kLag, {0.98, 0.98, 0.98, 0.98, 0.98, 0.98, 0.98, 0.98});
  const SearchResult r = Choose(best);
  EXPECT_EQ(r.best_level, CalibrationReport::kTwoStates);
  EXPECT_EQ(r.chosen.level, CalibrationReport::kTwoStates);
  EXPECT_FALSE(r.fell_back_to_constant);
}

// The rule itself: the simplest level within a standard error of the best that beats the
// constant stands; when no level beats the constant, the constant stands and says so.
TEST(ThermalSearch, TheSimplestLevelNearTheBestThatBeatsTheConstantStands) {
  LevelBests best;
  Put(best, CalibrationReport::kConstant, {1.0, 1.1, 0.9, 1.0, 1.05, 0.95, 1.0, 1.0});
  Put(best, CalibrationReport::kStatic, {0.80, 0.90, 0.71, 0.80, 0.86, 0.75, 0.80, 0.79});
  Put(best, CalibrationReport::kLag, {0.75, 0.92, 0.70, 0.82, 0.83, 0.77, 0.78, 0.80});
  SearchResult r = Choose(best);
  EXPECT_EQ(r.best_level, CalibrationReport::kLag);
  EXPECT_EQ(r.chosen.level, CalibrationReport::kStatic);
  // The best level's gain over the constant within the folds' noise: the constant, which says
  // that a richer level scored best.
  Put(best, CalibrationReport::kStatic, {0.9, 1.2, 0.8, 1.1, 1.0, 0.95, 1.05, 0.98});
  Put(best, CalibrationReport::kLag, {1.1, 0.9, 0.85, 0.95, 1.0, 0.9, 1.1, 0.95});
  r = Choose(best);
  EXPECT_EQ(r.chosen.level, CalibrationReport::kConstant);
  EXPECT_TRUE(r.fell_back_to_constant);
}

}  // namespace
}  // namespace gyrodrift::drift::internal
