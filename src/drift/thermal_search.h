// The structure search of the thermal identification (thermal_model.h, "Structure"): held-out
// scores of column subsets from fold moments, the nested ladder of structures and the
// one-standard-error rule. Private to src/drift.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <utility>
#include <vector>

#include "gyrodrift/drift/thermal_model.h"

namespace gyrodrift::drift::internal {

// Fold schemes: what a held-out fold tests.
enum FoldScheme { kTimeBlocks = 0, kRegimes = 1, kRangeEnds = 2, kSchemes = 3 };

// A held-out fold: row ranges [begin, end) of one scheme.
struct FoldRows {
  FoldScheme scheme = kTimeBlocks;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> ranges;
};

// Held-out least squares on column subsets of a design, from moments: each fold's Gram matrix
// over its logged rows, the training part's being the whole run's less the fold's. The time
// blocks must partition the rows (the whole run's moments are their sum).
class FoldScores {
 public:
  struct Fold {
    FoldScheme scheme = kTimeBlocks;
    std::vector<std::pair<Eigen::Index, Eigen::Index>> ranges;
    Eigen::MatrixXd g, g_train;
    Eigen::VectorXd b, b_train;
    double yy = 0.0;
    double logged = 0.0;  // samples
    double weight = 0.0;  // in the fold average: each scheme weighs equally
  };

  // x: N x M design; yc: the centred target (0 where not logged); weight: 1 logged, 0 made up.
  // Only the folds of `scored` schemes enter Mean and StandardError (the others serve
  // SchemeMean). prior_samples: the fits' ridge on every column but the intercept, in training
  // samples at the column's mean square (CalibrationReport::prior_samples).
  FoldScores(const Eigen::MatrixXd& x, const Eigen::VectorXd& yc, const Eigen::VectorXd& weight,
             const std::vector<FoldRows>& folds, unsigned scored = 1u << kTimeBlocks,
             double prior_samples = 0.0);

  const std::vector<Fold>& folds() const { return folds_; }
  const Eigen::MatrixXd& gram() const { return g_total_; }  // of every logged row
  // The training part's least-squares weights of fold f on the columns `cols`.
  Eigen::VectorXd Weights(const Fold& f, const std::vector<int>& cols) const;
  // The least-squares weights of the columns `cols` on every logged row.
  Eigen::VectorXd FullWeights(const std::vector<int>& cols) const;
  // Held-out mean square error of every scored fold (NaN at the others, which `every_fold`
  // scores too: the search needs the scored folds only, the report the rest for three subsets).
  Eigen::VectorXd Scores(const std::vector<int>& cols, bool every_fold = false) const;
  // The fold-weighted mean of per-fold values (scores or their differences), over every fold or
  // over the folds of one scheme.
  double Mean(const Eigen::VectorXd& per_fold) const;
  double SchemeMean(const Eigen::VectorXd& per_fold, FoldScheme scheme) const;
  // Standard error of that weighted mean, the folds taken as independent.
  double StandardError(const Eigen::VectorXd& per_fold) const;
  // Time-block mean square error (pooled over samples), and the held-out residual of the time
  // blocks at every row (0 where not logged).
  double TimeMse(const std::vector<int>& cols) const;
  Eigen::VectorXd TimeResidual(const std::vector<int>& cols) const;

 private:
  const Eigen::MatrixXd& x_;
  const Eigen::VectorXd& yc_;
  const Eigen::VectorXd& weight_;
  double prior_samples_;
  Eigen::MatrixXd g_total_;
  Eigen::VectorXd b_total_;
  std::vector<Fold> folds_;
};

// The candidate design's layout: the intercept, per channel its static powers 1..static_powers,
// then per candidate state `state_columns` (powers and rate) and `widths` hysteresis columns.
struct DesignLayout {
  int channels = 1;
  int static_powers = 3;
  int candidates = 0;
  int state_columns = 4;
  int widths = 0;
  int StaticColumn(int channel, int power) const { return 1 + channel * static_powers + power - 1; }
  int StateColumn(int candidate, int column) const {
    return 1 + channels * static_powers + candidate * (state_columns + widths) + column;
  }
  int WidthColumn(int candidate, int w) const { return StateColumn(candidate, state_columns + w); }
};

// A subset of the candidate design's columns.
struct Subset {
  std::vector<int> cols{0};   // the intercept first
  std::vector<int> states;    // candidate indices
  int static_power = 0;       // of every channel
  bool rates = true;          // the states' rate columns enter
  int hysteresis_state = -1;  // position in `states` of the state whose H_w is the last column
  int hysteresis_width = -1;  // index of w in the widths tried
  int level = CalibrationReport::kConstant;
  double score = std::numeric_limits<double>::infinity();  // fold-weighted held-out MSE
  Eigen::VectorXd fold_scores;
};

// What the search found: the chosen subset, the best of each level, and the two references.
struct SearchResult {
  Subset chosen;
  Subset constant, static_full;  // static_full: powers of T up to the layout's static_powers
  int best_level = 0;
  double best_score = 0.0;             // of the best level
  bool fell_back_to_constant = false;  // the constant, although a richer level scored best
  // The least held-out score among the subsets SteadySupport left out.
  double best_unsupported_score = std::numeric_limits<double>::infinity();
};

// What the calibration's temperatures support at steady state: the candidate design's columns at
// steady temperatures (every state at its channel's temperature, rates and hysteresis 0) on a grid
// over the calibrated range, and the band the centred target's block means spanned. A fit whose
// steady-state drift leaves that band, widened by its own width on either side, claims a curve the
// run never showed: two plateaus, between which a cubic is free to swing [choice, docs/drift.md
// 4.10: the grid and the widening measured on family units 1-20].
struct SteadySupport {
  Eigen::MatrixXd design;  // grid points x candidate columns
  double low = 0.0, high = 0.0;
  // Whether the weights w of the columns `cols` keep the steady-state drift within the band.
  bool Holds(const Eigen::VectorXd& w, const std::vector<int>& cols) const;
};

// The steady support of a candidate design (CandidateDesign's layout and candidates): steady
// temperatures across the calibrated range (kSteadyPoints), every channel along its own range
// together (the channels of one gyro warm together), and the band of the means of the centred
// target yc over the logged samples of each whole block of `block` samples.
SteadySupport SteadySupportOf(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                              const Eigen::VectorXd& yc, const Eigen::VectorXd& weight,
                              Eigen::Index block, const ThermalRegression& model,
                              const DesignLayout& layout,
                              const std::vector<ThermalState>& candidates);

struct SearchRules {
  int max_states = 2;
  double max_condition = 1e8;
  double standard_errors = 1.0;
  // The run showed both directions of temperature change (a heating and a cooling ramp); else no
  // structure holds a lag difference (two states, or a state beside the static term), whose sign
  // follows the direction, nor a hysteresis term, which tells the directions apart.
  bool both_directions = true;
  // Subsets that SteadySupport rejects are not candidates (null: no check).
  const SteadySupport* steady = nullptr;
};

// The best subset of each level of the ladder (CalibrationReport's levels, the constant first).
inline constexpr int kLevels = CalibrationReport::kHysteresis + 1;
using LevelBests = std::array<Subset, kLevels>;

// The rule of thermal_model.h's "Structure" on the levels' bests (unscored levels have an infinite
// score): result.best_level and best_score, and as result.chosen the constant when it is within
// reach of the best (then the best does not beat it), else the simplest level that is not
// clearly worse than the best and clearly better than result.constant (by rules.standard_errors
// standard errors of the paired fold differences each; the best always qualifies then).
void ChooseLevel(const FoldScores& scores, const SearchRules& rules, const LevelBests& best,
                 SearchResult& result);

// The nested search of thermal_model.h's "Structure" over the design's subsets.
SearchResult SearchStructure(const FoldScores& scores, const DesignLayout& layout,
                             const SearchRules& rules);

}  // namespace gyrodrift::drift::internal
