// The one-standard-error rule of the thermal identification on hand-made fold scores
// (drift/thermal_search.h, ChooseLevel; docs/drift.md 4.8).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <initializer_list>
#include <limits>
#include <vector>

#include "drift/thermal_search.h"

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

Subset Level(int level, std::initializer_list<double> per_fold) {
  Subset s;
  s.level = level;
  s.fold_scores = Eigen::Map<const Eigen::VectorXd>(per_fold.begin(),
                                                    static_cast<Eigen::Index>(per_fold.size()));
  s.score = s.fold_scores.mean();
  return s;
}

SearchResult Choose(const LevelBests& best) {
  const EightFolds f;
  const FoldScores scores(f.x, f.y, f.weight, f.rows);
  SearchResult result;
  result.constant = best[CalibrationReport::kConstant];
  ChooseLevel(scores, SearchRules{}, best, result);
  return result;
}

// Unit 54 of the family's 16-h calibrations, in miniature: one state with its rate comes within a
// standard error of the best (two states) but has one bad fold, so it does not beat the constant;
// the two states beat the constant on every fold. The choice passes to the two states (before:
// the constant, which cost that unit 13 points of the mission's drift).
TEST(ThermalSearch, ALevelThatDoesNotBeatTheConstantPassesTheChoiceOn) {
  LevelBests best;
  best[CalibrationReport::kConstant] = Level(0, {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0});
  best[CalibrationReport::kOneState] = Level(CalibrationReport::kOneState, {0.9, 0.9, 0.9, 8.0, 0.9, 0.9, 0.9, 0.9});
  best[CalibrationReport::kTwoStates] = Level(CalibrationReport::kTwoStates, {0.95, 0.94, 0.96, 0.95, 0.93, 0.96, 0.95, 0.94});
  // Static powers and the lagged level clearly worse than the best, hysteresis not scored; one
  // state's mean is the best's + 0.84 with a standard error of 0.89 (one fold): within reach.
  best[CalibrationReport::kStatic] = Level(CalibrationReport::kStatic, {0.99, 0.99, 0.99, 0.99, 0.99, 0.99, 0.99, 0.99});
  best[CalibrationReport::kLag] = Level(CalibrationReport::kLag, {0.98, 0.98, 0.98, 0.98, 0.98, 0.98, 0.98, 0.98});
  const SearchResult r = Choose(best);
  EXPECT_EQ(r.best_level, 4);
  EXPECT_EQ(r.chosen.level, 4);
  EXPECT_FALSE(r.fell_back_to_constant);
}

// The rule itself: the simplest level within a standard error of the best that beats the
// constant stands; when no level beats the constant, the constant stands and says so.
TEST(ThermalSearch, TheSimplestLevelNearTheBestThatBeatsTheConstantStands) {
  LevelBests best;
  best[CalibrationReport::kConstant] = Level(0, {1.0, 1.1, 0.9, 1.0, 1.05, 0.95, 1.0, 1.0});
  best[1] = Level(1, {0.80, 0.90, 0.71, 0.80, 0.86, 0.75, 0.80, 0.79});
  best[2] = Level(2, {0.75, 0.92, 0.70, 0.82, 0.83, 0.77, 0.78, 0.80});
  SearchResult r = Choose(best);
  EXPECT_EQ(r.best_level, 2);
  EXPECT_EQ(r.chosen.level, 1);
  // The best level's gain over the constant within the folds' noise: the constant, which says
  // that a richer level scored best.
  best[1] = Level(1, {0.9, 1.2, 0.8, 1.1, 1.0, 0.95, 1.05, 0.98});
  best[2] = Level(2, {1.1, 0.9, 0.85, 0.95, 1.0, 0.9, 1.1, 0.95});
  r = Choose(best);
  EXPECT_EQ(r.chosen.level, CalibrationReport::kConstant);
  EXPECT_TRUE(r.fell_back_to_constant);
}

}  // namespace
}  // namespace gyrodrift::drift::internal
