// The structure search of the thermal identification: fold moments, held-out scores, the steady
// support, the nested ladder and the one-standard-error rule (thermal_search.h).
#include "thermal_search.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "thermal_columns.h"

namespace gyrodrift::drift::internal {
namespace {

constexpr double kRelativeRidge = 1e-10;  // on the unit-diagonal Gram of a subset
// Steady temperatures at which a candidate's drift is held to the run's band (SteadySupportOf).
constexpr Eigen::Index kSteadyPoints = 61;

// Calls f(begin, length) for every run of logged rows (weight > 0) within [begin, end).
template <typename F>
void ForLoggedRuns(const Eigen::VectorXd& weight, Eigen::Index begin, Eigen::Index end, F&& f) {
  Eigen::Index i = begin;
  while (i < end) {
    while (i < end && weight[i] <= 0.0) ++i;
    const Eigen::Index start = i;
    while (i < end && weight[i] > 0.0) ++i;
    if (i > start) f(start, i - start);
  }
}

// Least squares on the columns `cols` of Gram G and moment b, solved with unit-diagonal scaling
// and a tiny ridge (the subsets' columns can be close to collinear), plus the ridge of
// `prior_samples` samples on every column but the intercept (column 0, whose Gram entry counts
// the samples).
Eigen::VectorXd SolveSubset(const Eigen::MatrixXd& g, const Eigen::VectorXd& b,
                            const std::vector<int>& cols, double prior_samples) {
  const double prior = prior_samples / std::max(g(0, 0), 1.0);
  const Eigen::Index m = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd a(m, m);
  Eigen::VectorXd rhs(m), d(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    d[i] = 1.0 / std::sqrt(std::max(g(cols[i], cols[i]), std::numeric_limits<double>::min()));
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    rhs[i] = b[cols[i]] * d[i];
    for (Eigen::Index j = 0; j < m; ++j) a(i, j) = g(cols[i], cols[j]) * d[i] * d[j];
    a(i, i) += kRelativeRidge + (cols[i] != 0 ? prior : 0.0);
  }
  Eigen::VectorXd w = a.ldlt().solve(rhs);
  return w.cwiseProduct(d);
}

// Condition number of the unit-diagonal Gram of the columns `cols`.
double Condition(const Eigen::MatrixXd& g, const std::vector<int>& cols) {
  const Eigen::Index m = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd a(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) {
      a(i, j) = g(cols[i], cols[j]) / std::sqrt(std::max(g(cols[i], cols[i]) * g(cols[j], cols[j]),
                                                         std::numeric_limits<double>::min()));
    }
  }
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues();
  return ev[0] > 0.0 ? ev[m - 1] / ev[0] : std::numeric_limits<double>::infinity();
}

}  // namespace

FoldScores::FoldScores(const Eigen::MatrixXd& x, const Eigen::VectorXd& yc,
                       const Eigen::VectorXd& weight, const std::vector<FoldRows>& folds,
                       unsigned scored, double prior_samples)
    : x_(x), yc_(yc), weight_(weight), prior_samples_(prior_samples) {
  const Eigen::Index m = x.cols();
  g_total_ = Eigen::MatrixXd::Zero(m, m);
  b_total_ = Eigen::VectorXd::Zero(m);
  std::array<int, kSchemes> per_scheme{};
  for (const FoldRows& rows : folds) {
    Fold f;
    f.scheme = rows.scheme;
    f.ranges = rows.ranges;
    f.g = Eigen::MatrixXd::Zero(m, m);
    f.b = Eigen::VectorXd::Zero(m);
    for (const auto& [begin, end] : rows.ranges) {
      ForLoggedRuns(weight, begin, end, [&](Eigen::Index start, Eigen::Index length) {
        const auto xu = x.middleRows(start, length);
        f.g.selfadjointView<Eigen::Lower>().rankUpdate(xu.transpose());
        f.b += xu.transpose() * yc.segment(start, length);
        f.yy += yc.segment(start, length).squaredNorm();
        f.logged += static_cast<double>(length);
      });
    }
    f.g = f.g.selfadjointView<Eigen::Lower>();
    if (f.scheme == kTimeBlocks) {
      g_total_ += f.g;
      b_total_ += f.b;
    }
    if (scored & (1u << f.scheme)) ++per_scheme[f.scheme];
    folds_.push_back(std::move(f));
  }
  const int schemes = static_cast<int>(
      std::count_if(per_scheme.begin(), per_scheme.end(), [](int c) { return c > 0; }));
  for (Fold& f : folds_) {
    f.g_train = g_total_ - f.g;
    f.b_train = b_total_ - f.b;
    f.weight = per_scheme[f.scheme] > 0 ? 1.0 / (schemes * per_scheme[f.scheme]) : 0.0;
  }
}

Eigen::VectorXd FoldScores::Weights(const Fold& f, const std::vector<int>& cols) const {
  return SolveSubset(f.g_train, f.b_train, cols, prior_samples_);
}

Eigen::VectorXd FoldScores::FullWeights(const std::vector<int>& cols) const {
  return SolveSubset(g_total_, b_total_, cols, prior_samples_);
}

bool SteadySupport::Holds(const Eigen::VectorXd& w, const std::vector<int>& cols) const {
  const double margin = high - low;
  for (Eigen::Index r = 0; r < design.rows(); ++r) {
    double drift = 0.0;
    for (size_t i = 0; i < cols.size(); ++i) {
      drift += w[static_cast<Eigen::Index>(i)] * design(r, cols[i]);
    }
    if (!(drift >= low - margin && drift <= high + margin)) return false;
  }
  return true;
}

SteadySupport SteadySupportOf(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                              const Eigen::VectorXd& yc, const Eigen::VectorXd& weight,
                              Eigen::Index block, const ThermalRegression& model,
                              const DesignLayout& layout,
                              const std::vector<ThermalState>& candidates) {
  SteadySupport support;
  support.design = Eigen::MatrixXd::Zero(kSteadyPoints, layout.StateColumn(layout.candidates, 0));
  const Eigen::VectorXd lo = temperatures_c.colwise().minCoeff().transpose();
  const Eigen::VectorXd hi = temperatures_c.colwise().maxCoeff().transpose();
  for (Eigen::Index g = 0; g < kSteadyPoints; ++g) {
    const double t = static_cast<double>(g) / (kSteadyPoints - 1);
    auto row = support.design.row(g);
    row[0] = 1.0;
    auto z = [&](int c) {
      const auto cu = static_cast<size_t>(c);
      return (lo[c] + t * (hi[c] - lo[c]) - model.centre_c[cu]) / model.scale_k[cu];
    };
    for (int c = 0; c < layout.channels; ++c) {
      const auto cu = static_cast<size_t>(c);
      for (int p = 1; p <= layout.static_powers; ++p) {
        row[layout.StaticColumn(c, p)] =
            TangentPower(z(c), p, model.static_min[cu], model.static_max[cu]);
      }
    }
    for (int j = 0; j < layout.candidates; ++j) {
      const ThermalState& s = candidates[static_cast<size_t>(j)];
      for (int p = 1; p < layout.state_columns; ++p) {  // the level's powers; the rate stays 0
        row[layout.StateColumn(j, p - 1)] = TangentPower(z(s.channel), p, s.level_min, s.level_max);
      }
    }
  }
  // Whole blocks, as the skill's and the summaries' (a last partial block dropped).
  support.low = std::numeric_limits<double>::infinity();
  support.high = -support.low;
  for (Eigen::Index begin = 0; begin + block <= yc.size(); begin += block) {
    const double logged = weight.segment(begin, block).sum();
    if (logged <= 0.0) continue;
    const double mean = yc.segment(begin, block).sum() / logged;  // yc is 0 where not logged
    support.low = std::min(support.low, mean);
    support.high = std::max(support.high, mean);
  }
  return support;
}

Eigen::VectorXd FoldScores::Scores(const std::vector<int>& cols, bool every_fold) const {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(folds_.size()),
                                                  std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < folds_.size(); ++k) {
    const Fold& f = folds_[k];
    if (f.weight == 0.0 && !every_fold) continue;
    const Eigen::VectorXd w = Weights(f, cols);
    double e = f.yy;
    for (size_t i = 0; i < cols.size(); ++i) {
      const double wi = w[static_cast<Eigen::Index>(i)];
      e -= 2.0 * wi * f.b[cols[i]];
      for (size_t j = 0; j < cols.size(); ++j) {
        e += wi * f.g(cols[i], cols[j]) * w[static_cast<Eigen::Index>(j)];
      }
    }
    out[static_cast<Eigen::Index>(k)] = std::max(0.0, e) / std::max(1.0, f.logged);
  }
  return out;
}

double FoldScores::Mean(const Eigen::VectorXd& per_fold) const {
  double sum = 0.0;
  for (size_t k = 0; k < folds_.size(); ++k) {
    if (folds_[k].weight > 0.0) sum += folds_[k].weight * per_fold[static_cast<Eigen::Index>(k)];
  }
  return sum;
}

double FoldScores::SchemeMean(const Eigen::VectorXd& per_fold, FoldScheme scheme) const {
  double sum = 0.0;
  int count = 0;
  for (size_t k = 0; k < folds_.size(); ++k) {
    if (folds_[k].scheme != scheme) continue;
    sum += per_fold[static_cast<Eigen::Index>(k)];
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

double FoldScores::StandardError(const Eigen::VectorXd& per_fold) const {
  // Each scheme's mean has variance s^2 / n; the schemes weigh equally in the mean.
  double variance = 0.0;
  int schemes = 0;
  for (int s = 0; s < kSchemes; ++s) {
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (size_t k = 0; k < folds_.size(); ++k) {
      if (folds_[k].scheme != s || folds_[k].weight == 0.0) continue;
      const double v = per_fold[static_cast<Eigen::Index>(k)];
      sum += v;
      sum2 += v * v;
      ++n;
    }
    if (n == 0) continue;
    ++schemes;
    if (n > 1) {
      const double mean = sum / n;
      variance += std::max(0.0, (sum2 - n * mean * mean) / (n - 1)) / n;
    }
  }
  return schemes > 0 ? std::sqrt(variance) / schemes : 0.0;
}

double FoldScores::TimeMse(const std::vector<int>& cols) const {
  const Eigen::VectorXd s = Scores(cols, /*every_fold=*/true);
  double sse = 0.0, logged = 0.0;
  for (size_t k = 0; k < folds_.size(); ++k) {
    if (folds_[k].scheme != kTimeBlocks) continue;
    sse += s[static_cast<Eigen::Index>(k)] * std::max(1.0, folds_[k].logged);
    logged += folds_[k].logged;
  }
  return logged > 0.0 ? sse / logged : 0.0;
}

Eigen::VectorXd FoldScores::TimeResidual(const std::vector<int>& cols) const {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(yc_.size());
  for (const Fold& f : folds_) {
    if (f.scheme != kTimeBlocks) continue;
    const Eigen::VectorXd w = Weights(f, cols);
    for (const auto& [begin, end] : f.ranges) {
      for (size_t i = 0; i < cols.size(); ++i) {
        r.segment(begin, end - begin) -=
            w[static_cast<Eigen::Index>(i)] * x_.col(cols[i]).segment(begin, end - begin);
      }
      r.segment(begin, end - begin) += yc_.segment(begin, end - begin);
      r.segment(begin, end - begin).array() *= weight_.segment(begin, end - begin).array();
    }
  }
  return r;
}

namespace {

// The ladder's candidates scored, keeping the best subset of each level.
class Ladder {
 public:
  Ladder(const FoldScores& scores, const DesignLayout& layout, const SearchRules& rules)
      : scores_(scores), layout_(layout), rules_(rules) {}

  // s scored, kept when it is the best of its level so far, well conditioned (ConsiderStates checks
  // the states' subsets before their hysteresis variants) and held by the steady support.
  Subset Consider(Subset s) {
    s.fold_scores = scores_.Scores(s.cols);
    s.score = scores_.Mean(s.fold_scores);
    if ((s.level == CalibrationReport::kStatic || s.level == CalibrationReport::kHysteresis) &&
        Condition(scores_.gram(), s.cols) > rules_.max_condition) {
      return s;
    }
    if (rules_.steady && s.cols.size() > 1 &&
        !rules_.steady->Holds(scores_.FullWeights(s.cols), s.cols)) {
      best_unsupported_score_ = std::min(best_unsupported_score_, s.score);
      return s;
    }
    if (s.score < best_[static_cast<size_t>(s.level)].score)
      best_[static_cast<size_t>(s.level)] = s;
    return s;
  }

  // Every set of at most `max_states` lag states from candidate `next` on, added to `chosen`.
  void VisitStates(std::vector<int>& chosen, int next, int max_states) {
    if (!chosen.empty()) ConsiderStates(chosen);
    if (static_cast<int>(chosen.size()) == max_states) return;
    for (int j = next; j < layout_.candidates; ++j) {
      chosen.push_back(j);
      VisitStates(chosen, j + 1, max_states);
      chosen.pop_back();
    }
  }

  const LevelBests& best() const { return best_; }
  double best_unsupported_score() const { return best_unsupported_score_; }

 private:
  // The lag states `chosen`: one state's level powers, or one or two states with their rates;
  // each with or without the linear static term; with the hysteresis term of one of the states.
  void ConsiderStates(const std::vector<int>& chosen) {
    for (int with_linear : {0, 1}) {
      for (bool rates : {false, true}) {
        if (!rates && chosen.size() > 1) continue;
        if (!rules_.both_directions && (chosen.size() > 1 || with_linear)) continue;
        Subset s;
        s.states = chosen;
        s.static_power = with_linear;
        s.rates = rates;
        s.level = !rates               ? CalibrationReport::kLag
                  : chosen.size() == 1 ? CalibrationReport::kOneState
                                       : CalibrationReport::kTwoStates;
        for (int c = 0; with_linear && c < layout_.channels; ++c) {
          s.cols.push_back(layout_.StaticColumn(c, 1));
        }
        for (int j : chosen) {
          for (int p = 0; p < layout_.state_columns - (rates ? 0 : 1); ++p) {
            s.cols.push_back(layout_.StateColumn(j, p));
          }
        }
        if (Condition(scores_.gram(), s.cols) > rules_.max_condition) continue;
        Consider(s);
        // A hysteresis term tells heating from cooling: a one-way run cannot identify it.
        if (!rates || !rules_.both_directions) continue;
        for (size_t k = 0; k < chosen.size(); ++k) {
          for (int w = 0; w < layout_.widths; ++w) {
            Subset h = s;
            h.level = CalibrationReport::kHysteresis;
            h.hysteresis_state = static_cast<int>(k);
            h.hysteresis_width = w;
            h.cols.push_back(layout_.WidthColumn(chosen[k], w));
            Consider(std::move(h));
          }
        }
      }
    }
  }

  const FoldScores& scores_;
  const DesignLayout& layout_;
  const SearchRules& rules_;
  LevelBests best_{};
  double best_unsupported_score_ = std::numeric_limits<double>::infinity();
};

}  // namespace

// A level within reach of the best that does not beat the constant (one bad fold can do that)
// passes the choice to the next richer one, not to the constant.
void ChooseLevel(const FoldScores& scores, const SearchRules& rules, const LevelBests& best,
                 SearchResult& result) {
  std::array<bool, kLevels> eligible{};
  for (int l = 0; l < kLevels; ++l) {
    eligible[static_cast<size_t>(l)] = std::isfinite(best[static_cast<size_t>(l)].score);
  }
  int b = 0;
  for (int l = 1; l < kLevels; ++l) {
    if (eligible[static_cast<size_t>(l)] &&
        best[static_cast<size_t>(l)].score < best[static_cast<size_t>(b)].score) {
      b = l;
    }
  }
  result.best_level = b;
  result.best_score = best[static_cast<size_t>(b)].score;
  const Subset& top = best[static_cast<size_t>(b)];
  const double k = rules.standard_errors;
  // Not clearly worse than the best, and clearly better than the constant.
  auto within_best = [&](const Subset& s) {
    const Eigen::VectorXd d = s.fold_scores - top.fold_scores;
    return scores.Mean(d) <= k * scores.StandardError(d);
  };
  auto beats_constant = [&](const Subset& s) {
    const Eigen::VectorXd d = s.fold_scores - result.constant.fold_scores;
    return scores.Mean(d) < -k * scores.StandardError(d);
  };
  result.chosen = result.constant;
  for (int l = 0; l <= b; ++l) {
    const Subset& s = best[static_cast<size_t>(l)];
    if (eligible[static_cast<size_t>(l)] && within_best(s) && (l == 0 || beats_constant(s))) {
      result.chosen = s;
      break;
    }
  }
  // The constant although a richer level scored best: that level did not beat it clearly (the
  // constant within reach of the best and the best beating the constant are complements).
  result.fell_back_to_constant = result.chosen.level == CalibrationReport::kConstant && b > 0;
}

SearchResult SearchStructure(const FoldScores& scores, const DesignLayout& layout,
                             const SearchRules& rules) {
  Ladder ladder(scores, layout, rules);
  SearchResult result;
  // The constant, then static powers of every channel.
  Subset constant;
  result.constant = ladder.Consider(constant);
  for (int p = 1; p <= layout.static_powers; ++p) {
    Subset s;
    s.level = CalibrationReport::kStatic;
    s.static_power = p;
    for (int c = 0; c < layout.channels; ++c) {
      for (int q = 1; q <= p; ++q) s.cols.push_back(layout.StaticColumn(c, q));
    }
    const Subset scored = ladder.Consider(std::move(s));
    if (p == layout.static_powers) result.static_full = scored;
  }
  // Then the lag states' subsets.
  std::vector<int> chosen;
  ladder.VisitStates(chosen, 0, std::min(rules.max_states, layout.candidates));
  ChooseLevel(scores, rules, ladder.best(), result);
  result.best_unsupported_score = ladder.best_unsupported_score();
  return result;
}

}  // namespace gyrodrift::drift::internal
