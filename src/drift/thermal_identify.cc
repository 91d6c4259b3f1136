// The identification of a thermal model from its calibration run (thermal_model.h): the candidate
// design, the folds, the structure search (thermal_search.h), the refit of the chosen columns with
// their uncertainty, the optional nonlinear correction and the calibration report
// (thermal_report.h).
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/records.h"
#include "gyrodrift/drift/thermal_model.h"
#include "gyrodrift/elm/elm.h"
#include "thermal_columns.h"
#include "thermal_folds.h"
#include "thermal_report.h"
#include "thermal_search.h"

namespace gyrodrift::drift {
namespace {

using internal::HysteresisColumns;
using internal::StateColumns;
using internal::StaticColumns;

constexpr double kBlockS = 600.0;            // blocks of the residual's batch means
constexpr double kShortBlockS = 10.0;        // blocks that measure the residual's fast noise
using internal::kShortestFold;
using internal::MakeFolds;
// The skill needs this many 10-min blocks of residual to tell slow error from noise.
constexpr int kLeastSkillBlocks = 4;
// Candidates of the nonlinear correction (hidden units ascending: they share one hidden layer).
constexpr std::array<int, 4> kCorrectionUnits{5, 10, 20, 40};
constexpr std::array<double, 4> kCorrectionRidge{1e-2, 1.0, 1e2, 1e4};
// A log of which less than this share of rows was logged (most rows made up, as io's
// kMostlyMadeUpShare words it; a duty-cycled log: 5 s of every 300 s leaves 480 samples of 8 h)
// has every coefficient but the intercept shrunk by a ridge worth kSparsePriorSamples logged
// samples at the regressor's mean square, in the fold fits and the final fit [choice,
// docs/drift.md 4.8: on duty-cycled family units no unit worse than raw].
constexpr double kSparseLoggedShare = 0.5;
constexpr double kSparsePriorSamples = 16.0;
// Beyond the rates of a direction the run never showed (a heat-up's cooling), a state's rate moves
// at this share of its slope: midway between no response (held) and the shown direction's (the
// Shupe and gradient terms are linear in the rate), which bounds the error by half either way
// [choice, docs/drift.md 4.8: heat-up units 1-20, from 0, 0.25, 0.5, 0.75 and 1].
constexpr double kUnshownRateShare = 0.5;

// Standard deviation about the mean (population).
double Sd(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return std::sqrt((x.array() - x.mean()).square().mean());
}



// Mean of squares of the block means of x over blocks of `block` samples, each mean taken over the
// block's logged samples (weight 1; 0 = made up across a gap), blocks without one left out.
double BlockMeanSquare(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block,
                       const Eigen::Ref<const Eigen::VectorXd>& weight,
                       double* logged_per_block = nullptr) {
  const Eigen::Index blocks = std::max<Eigen::Index>(1, x.size() / block);
  if (x.size() < block) block = x.size();
  double sum = 0.0;
  int counted = 0;
  for (Eigen::Index i = 0; i < blocks; ++i) {
    const double w = weight.segment(i * block, block).sum();
    if (w <= 0.0) continue;
    const double m = x.segment(i * block, block).dot(weight.segment(i * block, block)) / w;
    sum += m * m;
    ++counted;
  }
  if (logged_per_block) *logged_per_block = counted > 0 ? weight.sum() / counted : 0.0;
  return counted > 0 ? sum / counted : 0.0;
}

// Every candidate column (internal::DesignLayout): the intercept, per channel its static powers
// 1..max_power, then per candidate state its powers, its rate and H_w for each of widths_k (each
// candidate learning its ranges; the model its channels' static ranges).
Eigen::MatrixXd CandidateDesign(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                double rate_hz, const std::vector<Eigen::Index>& record_starts,
                                ThermalRegression& model, const internal::DesignLayout& layout,
                                const std::vector<double>& widths_k, bool heating, bool cooling,
                                std::vector<ThermalState>& candidates) {
  const int channels = static_cast<int>(temperatures_c.cols());
  Eigen::MatrixXd x(temperatures_c.rows(), layout.StateColumn(layout.candidates, 0));
  Eigen::VectorXd level;
  x.col(0).setOnes();
  for (int c = 0; c < channels; ++c) {
    const auto cu = static_cast<size_t>(c);
    const Eigen::VectorXd z =
        (temperatures_c.col(c).array() - model.centre_c[cu]) / model.scale_k[cu];
    model.static_min.push_back(z.minCoeff());
    model.static_max.push_back(z.maxCoeff());
    StaticColumns(z, layout.static_powers, model.static_min[cu], model.static_max[cu],
                  x.middleCols(layout.StaticColumn(c, 1), layout.static_powers));
  }
  for (size_t j = 0; j < candidates.size(); ++j) {
    const auto c = static_cast<size_t>(candidates[j].channel);
    StateColumns(temperatures_c.col(candidates[j].channel), candidates[j], model.order,
                 model.max_power, 1.0 / rate_hz, model.centre_c[c], model.scale_k[c],
                 /*learn_range=*/true, /*within_support=*/false, record_starts, widths_k,
                 x.middleCols(layout.StateColumn(static_cast<int>(j), 0),
                              layout.state_columns + layout.widths),
                 level);
    // The rates' support is their sign: a direction the run showed extrapolates (the Shupe and
    // gradient terms are linear in the rates), one it never showed moves at a share of its slope.
    if (heating) candidates[j].rate_max = std::numeric_limits<double>::infinity();
    if (cooling) candidates[j].rate_min = -std::numeric_limits<double>::infinity();
    candidates[j].rate_beyond = kUnshownRateShare;
  }
  return x;
}


// The nonlinear correction of the header comment: its candidates on one shared hidden layer of
// the chosen regressors xs (intercept left out), scored against each fold's linear fit on the
// time-block folds (each one range; every sample logged). Null when none lowers the
// cross-validated error; the report says what was tried.
std::shared_ptr<const Learner> FitCorrection(const internal::FoldScores& cv,
                                             const Eigen::MatrixXd& xs, const Eigen::MatrixXd& z,
                                             const Eigen::VectorXd& yc,
                                             const internal::Subset& subset,
                                             const Eigen::VectorXd& residual, std::uint64_t seed,
                                             CalibrationReport& report) {
  const Eigen::Index n = xs.rows();
  elm::ElmOptions eo;
  eo.hidden_units = kCorrectionUnits.back();
  eo.ridge_c = 1.0;
  eo.seed = SeedFor(seed, "thermal-correction");
  const Execution one_thread{.threads = 1};
  const elm::ElmFit widest = elm::Fit(z, yc, eo, one_thread);
  const Eigen::MatrixXd h = elm::HiddenLayer(widest.model, z, 1);
  const Eigen::MatrixXd hth = h.transpose() * h;
  std::vector<double> error(kCorrectionUnits.size() * kCorrectionRidge.size(), 0.0);
  double linear_error = 0.0;
  for (const internal::FoldScores::Fold& f : cv.folds()) {
    if (f.scheme != internal::kTimeBlocks) continue;
    const auto [begin, end] = f.ranges.front();
    const Eigen::VectorXd r = yc - xs * cv.Weights(f, subset.cols);
    const Eigen::Index len = end - begin;
    const auto r_fold = r.segment(begin, len);
    // The network's target: the training part's residual, standardised as elm::Fit does.
    const double mean = (r.sum() - r_fold.sum()) / static_cast<double>(n - len);
    const double sd = std::sqrt(std::max(
        ((r.array() - mean).square().sum() - (r_fold.array() - mean).square().sum()) /
            static_cast<double>(n - len),
        std::numeric_limits<double>::min()));
    const Eigen::VectorXd t = (r.array() - mean) / sd;
    const auto h_fold = h.middleRows(begin, len);
    const Eigen::MatrixXd hth_train = hth - h_fold.transpose() * h_fold;
    const Eigen::VectorXd ht_train =
        h.transpose() * t - h_fold.transpose() * t.segment(begin, len);
    linear_error += r_fold.squaredNorm();
    size_t i = 0;
    for (int units : kCorrectionUnits) {
      for (double c : kCorrectionRidge) {
        Eigen::MatrixXd a = hth_train.topLeftCorner(units, units);
        a.diagonal().array() += 1.0 / c;
        const Eigen::VectorXd beta = a.ldlt().solve(ht_train.head(units));
        const Eigen::VectorXd predicted = (h_fold.leftCols(units) * beta).array() * sd + mean;
        error[i++] += (r_fold - predicted).squaredNorm();
      }
    }
  }
  const size_t chosen =
      static_cast<size_t>(std::min_element(error.begin(), error.end()) - error.begin());
  report.cv_rmse_nonlinear = std::sqrt(error[chosen] / static_cast<double>(n));
  if (!(error[chosen] < linear_error)) return nullptr;
  LearnerOptions lo;
  lo.kind = LearnerKind::kElm;
  lo.elm.selection = elm::Selection::kFixed;
  lo.elm.hidden_units = kCorrectionUnits[chosen / kCorrectionRidge.size()];
  lo.elm.ridge_c = kCorrectionRidge[chosen % kCorrectionRidge.size()];
  lo.seed = eo.seed;
  report.nonlinear_units = lo.elm.hidden_units;
  report.nonlinear_ridge_c = lo.elm.ridge_c;
  return FitLearner(z, residual, lo, one_thread);
}

// Samples in a block of `seconds`, at least 1 and at most a quarter of the run.
Eigen::Index BlockSamples(double seconds, double rate_hz, Eigen::Index n) {
  return std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::round(seconds * rate_hz)), 1,
                                  std::max<Eigen::Index>(1, n / 4));
}

// The logged-sample weights (1 logged, 0 made up across a gap), after checking the inputs.
Eigen::VectorXd CheckedWeights(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                               const Eigen::Ref<const Eigen::VectorXd>& y, double rate_hz,
                               const ThermalModelOptions& options,
                               const ThermalIdentification& run) {
  options.Validate();
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
  const Eigen::Index n = y.size();
  const int channels = static_cast<int>(temperatures_c.cols());
  if (channels < 1 || temperatures_c.rows() != n) {
    throw DataError("thermal identification needs temperature columns of " + std::to_string(n) +
                    " samples (the target's), got " + std::to_string(temperatures_c.rows()) +
                    " x " + std::to_string(channels));
  }
  if (!run.logged.empty() && static_cast<Eigen::Index>(run.logged.size()) != n) {
    throw DataError("thermal identification: " + std::to_string(run.logged.size()) +
                    " logged-sample flags for " + std::to_string(n) + " samples");
  }
  Eigen::VectorXd weight = Eigen::VectorXd::Ones(n);
  for (size_t i = 0; i < run.logged.size(); ++i) {
    weight[static_cast<Eigen::Index>(i)] = run.logged[i];
  }
  const double n_logged = weight.sum();
  // Only the logged samples are read (as FitDriftModel checks them): a made-up one may be
  // anything, NaN included.
  RequireFiniteLogged("target", y, run.logged, 1);
  if (n_logged < 2 * kShortestFold) {
    throw DataError("calibration run of " + std::to_string(static_cast<long>(n_logged)) +
                    " logged samples is too short to cross-validate a thermal model (at least " +
                    std::to_string(2 * kShortestFold) + " needed)");
  }
  if (run.nonlinear && n_logged < static_cast<double>(n)) {
    throw UsageError("the nonlinear correction needs every sample logged (no gaps carried)");
  }
  CheckRecordStarts(run.record_starts, n);
  for (int c = 0; c < channels; ++c) {
    RequireFiniteSignal("temperature", temperatures_c.col(c), n);
    RequireVaryingSignal("temperature", temperatures_c.col(c),
                         "a thermal model needs a calibration run whose temperature changes");
  }
  return weight;
}

// One identification's working set: the candidate design and its fold scores.
struct Search {
  std::vector<ThermalState> candidates;
  std::vector<double> widths_k;
  internal::DesignLayout layout;
  Eigen::MatrixXd x;
  Eigen::VectorXd yc;  // the target centred on its logged mean, 0 where not logged
  std::unique_ptr<internal::FoldScores> scores;
  internal::SteadySupport steady;
  internal::SearchResult result;
  internal::RunRegimes regimes;
};

// The calibration's description and folds in the report, then the structure search; the model
// takes the chosen structure (its coefficients come from RefitChosen).
void ChooseStructure(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                     const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::VectorXd& weight,
                     const ThermalModelOptions& options, const ThermalIdentification& run,
                     ThermalRegression& model, Search& search) {
  const Eigen::Index n = y.size();
  const int channels = static_cast<int>(temperatures_c.cols());
  CalibrationReport& report = model.report;
  report.duration_s = static_cast<double>(n) / model.rate_hz;
  report.records = static_cast<int>(run.record_starts.size()) + 1;
  const std::vector<ThermalSegment> segments = internal::RecordSegments(
      temperatures_c.col(0), model.rate_hz, options.ramp_rate_k_per_min, run.record_starts);
  search.regimes =
      internal::DescribeRun(temperatures_c, model.rate_hz, segments, run.record_starts, report);
  const std::vector<internal::FoldRows> folds =
      MakeFolds(temperatures_c.col(0), segments, weight, options);
  for (const internal::FoldRows& f : folds) {
    report.folds += f.scheme == internal::kTimeBlocks;
    report.regime_folds += f.scheme == internal::kRegimes;
    report.range_folds += f.scheme == internal::kRangeEnds;
  }
  if (report.folds < 2) {
    throw DataError("calibration run of " + std::to_string(n) +
                    " samples is too short to cross-validate a thermal model (at least " +
                    std::to_string(2 * kShortestFold) + " logged samples in each of 2 blocks)");
  }
  for (int c = 0; c < channels; ++c) {
    for (double tau : options.Grid(report.duration_s)) search.candidates.push_back({c, tau});
  }
  const double logged = weight.sum();
  report.hysteresis_tried = options.TriesHysteresis(logged / model.rate_hz);
  if (report.hysteresis_tried) search.widths_k = options.hysteresis_widths_k;
  // A run that never sat in the middle of its range shows no curve there (docs/drift.md 4.11).
  if (search.regimes.mid_range_s < internal::kCurveSupportS) model.max_power = 1;
  search.layout = {channels, model.max_power, static_cast<int>(search.candidates.size()),
                   model.max_power + 1, static_cast<int>(search.widths_k.size())};
  const bool heating = report.max_heating_k_per_min >= 2.0 * options.ramp_rate_k_per_min;
  const bool cooling = report.max_cooling_k_per_min >= 2.0 * options.ramp_rate_k_per_min;
  search.x = CandidateDesign(temperatures_c, model.rate_hz, run.record_starts, model,
                             search.layout, search.widths_k, heating, cooling, search.candidates);
  const double mean = y.dot(weight) / logged;
  search.yc = ((y.array() - mean) * weight.array()).matrix();
  report.prior_samples =
      logged < kSparseLoggedShare * static_cast<double>(n) ? kSparsePriorSamples : 0.0;
  // The choice is scored on the time blocks; the held-out regimes and range ends are reported
  // (scoring or gating on them chose worse models on the family: docs/drift.md 4.8).
  search.scores = std::make_unique<internal::FoldScores>(
      search.x, search.yc, weight, folds, 1u << internal::kTimeBlocks, report.prior_samples);
  search.steady = internal::SteadySupportOf(temperatures_c, search.yc, weight,
                                            BlockSamples(kBlockS, model.rate_hz, n), model,
                                            search.layout, search.candidates);
  // Holds (plateaus logged apart) show no response to change: a lag state is its temperature
  // there, and what it adds is the settling of a sensor (docs/drift.md 4.11).
  const bool holds =
      !heating && !cooling && search.regimes.widest_record_k < internal::kShortestSpanK;
  search.result =
      internal::SearchStructure(*search.scores, search.layout,
                                {holds ? 0 : options.max_states, options.max_condition,
                                 options.standard_errors, heating && cooling, &search.steady});
  const internal::Subset& best = search.result.chosen;
  model.static_power.assign(static_cast<size_t>(channels), best.static_power);
  for (int j : best.states) model.states.push_back(search.candidates[static_cast<size_t>(j)]);
  if (best.hysteresis_state >= 0) {
    model.hysteresis_state = best.hysteresis_state;
    model.hysteresis_width_k = search.widths_k[static_cast<size_t>(best.hysteresis_width)];
  }
}

// The search's held-out errors in the report: the chosen structure's, the best level's and the
// references', on the time blocks and on the held-out regimes and range ends.
void ReportHeldOut(const Search& search, CalibrationReport& report) {
  const internal::SearchResult& s = search.result;
  report.level = s.chosen.level;
  report.best_level = s.best_level;
  report.held_out_rmse = std::sqrt(s.chosen.score);
  report.held_out_rmse_constant = std::sqrt(s.constant.score);
  report.held_out_rmse_static = std::sqrt(s.static_full.score);
  report.held_out_rmse_best = std::sqrt(s.best_score);
  if (report.regime_folds + report.range_folds == 0) return;
  auto regimes = [&](const internal::Subset& subset) {
    const Eigen::VectorXd every = search.scores->Scores(subset.cols, /*every_fold=*/true);
    const int r = report.regime_folds > 0, e = report.range_folds > 0;
    return std::sqrt((search.scores->SchemeMean(every, internal::kRegimes) * r +
                      search.scores->SchemeMean(every, internal::kRangeEnds) * e) /
                     (r + e));
  };
  report.regime_rmse = regimes(s.chosen);
  report.regime_rmse_constant = regimes(s.constant);
  report.regime_rmse_static = regimes(s.static_full);
}

// Least squares of ys on the unit-scaled columns xn (the intercept first) by QR, with the ridge
// of `prior_samples` samples on every column but the intercept as rows below the design.
Eigen::VectorXd SolveWithPrior(const Eigen::MatrixXd& xn, const Eigen::VectorXd& ys,
                               double prior_samples) {
  if (prior_samples <= 0.0) return Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(xn).solve(ys);
  const Eigen::Index rows = xn.rows(), p = xn.cols();
  Eigen::MatrixXd xa = Eigen::MatrixXd::Zero(rows + p - 1, p);
  Eigen::VectorXd ya = Eigen::VectorXd::Zero(rows + p - 1);
  xa.topRows(rows) = xn;
  ya.head(rows) = ys;
  const double prior = std::sqrt(prior_samples / static_cast<double>(rows));
  for (Eigen::Index i = 1; i < p; ++i) xa(rows + i - 1, i) = prior;
  return Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(xa).solve(ya);
}

// The chosen columns refitted on the logged samples (SolveWithPrior, the report's ridge), in the
// model's coefficient slots (a state whose rate did not enter keeps a rate coefficient of 0), with
// their covariance: the residual variance inflated by its correlation (batch means over kBlockS).
// Returns the residual at every row (0 where not logged).
Eigen::VectorXd RefitChosen(const Eigen::Ref<const Eigen::VectorXd>& y,
                            const Eigen::VectorXd& weight, const Search& search,
                            ThermalRegression& model, Eigen::MatrixXd& gram) {
  const internal::Subset& best = search.result.chosen;
  const Eigen::Index n = y.size();
  const Eigen::Index p = static_cast<Eigen::Index>(best.cols.size());
  const Eigen::Index rows = static_cast<Eigen::Index>(weight.sum());
  Eigen::MatrixXd xs(rows, p);
  Eigen::VectorXd ys(rows);
  for (Eigen::Index i = 0, r = 0; i < n; ++i) {
    if (weight[i] <= 0.0) continue;
    for (Eigen::Index k = 0; k < p; ++k) xs(r, k) = search.x(i, best.cols[static_cast<size_t>(k)]);
    ys[r++] = y[i];
  }
  Eigen::VectorXd scale(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    scale[i] = 1.0 / std::max(xs.col(i).norm(), std::numeric_limits<double>::min());
  }
  const Eigen::MatrixXd xn = xs * scale.asDiagonal();
  const Eigen::VectorXd fitted =
      scale.asDiagonal() * SolveWithPrior(xn, ys, model.report.prior_samples);
  // Where each fitted column sits among the model's m regressors.
  std::vector<Eigen::Index> slot;
  Eigen::Index k = 1 + best.static_power * model.channels();
  for (Eigen::Index i = 0; i < k; ++i) slot.push_back(i);
  for (size_t j = 0; j < best.states.size(); ++j, k += model.max_power + 1) {
    for (int q = 0; q < model.max_power + (best.rates ? 1 : 0); ++q) slot.push_back(k + q);
  }
  if (best.hysteresis_state >= 0) slot.push_back(k++);
  model.coefficients = Eigen::VectorXd::Zero(k);
  for (Eigen::Index i = 0; i < p; ++i) model.coefficients[slot[static_cast<size_t>(i)]] = fitted[i];

  Eigen::VectorXd residual = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd r = ys - xs * fitted;
  const double r_mean = r.mean();
  for (Eigen::Index i = 0, j = 0; i < n; ++i) {
    if (weight[i] > 0.0) residual[i] = r[j++] - r_mean;
  }
  const double variance =
      residual.squaredNorm() / std::max(1.0, static_cast<double>(rows - p));
  double logged_per_block = 0.0;
  const double block_ms =
      BlockMeanSquare(residual, BlockSamples(kBlockS, model.rate_hz, n), weight, &logged_per_block);
  const double inflation =
      variance > 0.0 ? std::max(1.0, logged_per_block * block_ms / variance) : 1.0;
  gram = xn.transpose() * xn;
  const Eigen::MatrixXd covariance = scale.asDiagonal() *
                                     gram.ldlt().solve(Eigen::MatrixXd::Identity(p, p)) *
                                     scale.asDiagonal() * (variance * inflation);
  model.covariance = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index i = 0; i < p; ++i) {
    for (Eigen::Index j = 0; j < p; ++j) {
      model.covariance(slot[static_cast<size_t>(i)], slot[static_cast<size_t>(j)]) =
          covariance(i, j);
    }
  }
  return residual;
}

// The slow part of a held-out residual: the mean square of its block means (kBlockS) less what
// the fast noise contributes to them, from the means of kShortBlockS blocks scaled to a block's
// logged samples (exact for white noise, and not fooled by the anti-correlated quantization noise
// that first differences would count as white). The noise share is measured once, on the chosen
// structure's refit residual.
class SlowError {
 public:
  SlowError(const Eigen::VectorXd& residual, const Eigen::VectorXd& weight, const Search& search,
            double rate_hz)
      : weight_(weight), scores_(*search.scores) {
    const Eigen::Index n = residual.size();
    block_ = BlockSamples(kBlockS, rate_hz, n);
    const Eigen::Index short_block = std::min(block_, BlockSamples(kShortBlockS, rate_hz, n));
    double logged_per_block = 0.0, logged_per_short_block = 0.0;
    BlockMeanSquare(residual, block_, weight, &logged_per_block);
    const double short_ms = BlockMeanSquare(residual, short_block, weight, &logged_per_short_block);
    white_share_ =
        logged_per_block > 0.0 ? short_ms * logged_per_short_block / logged_per_block : 0.0;
  }
  // Of the time blocks' held-out residual of the columns `cols`.
  double operator()(const std::vector<int>& cols) const {
    return std::max(0.0,
                    BlockMeanSquare(scores_.TimeResidual(cols), block_, weight_) - white_share_);
  }

 private:
  const Eigen::VectorXd& weight_;
  const internal::FoldScores& scores_;
  Eigen::Index block_ = 1;
  double white_share_ = 0.0;
};

// The slow mean squares of the chosen structure's and the constant's held-out residuals.
struct SlowParts {
  double chosen_ms = 0.0;
  double constant_ms = 0.0;
};

// The slow part of the cross-validated residual (model.cv_slow_sd) and the skill against the
// constant on it; returns both slow parts for the autopilot form's share.
SlowParts SlowErrorAndSkill(const SlowError& slow_ms, const Search& search,
                            ThermalRegression& model) {
  const double chosen_ms = slow_ms(search.result.chosen.cols);
  const double constant_ms = slow_ms({0});
  model.cv_slow_sd = std::sqrt(chosen_ms);
  CalibrationReport& report = model.report;
  report.cv_rmse = std::sqrt(search.scores->TimeMse(search.result.chosen.cols));
  report.cv_rmse_constant = std::sqrt(search.scores->TimeMse({0}));
  if (static_cast<double>(search.yc.size()) < kLeastSkillBlocks * kBlockS * model.rate_hz) {
    report.skill = std::numeric_limits<double>::quiet_NaN();
  } else {
    report.skill = constant_ms > 0.0 ? 1.0 - chosen_ms / constant_ms : 0.0;
  }
  return {chosen_ms, constant_ms};
}

// The autopilot form (thermal_model.h) of channel 0: its degree by the rule on the search's fold
// scores (channel 0's static columns span the polynomials of dT of each degree), its coefficients
// refitted on the logged samples in dT scaled to the half range, its share of the slow drift the
// full model removes.
void FitAutopilotForm(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                      const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::VectorXd& weight,
                      const Search& search, double standard_errors, const SlowError& slow_ms,
                      const SlowParts& slow, ThermalRegression& model) {
  const internal::FoldScores& scores = *search.scores;
  std::vector<std::vector<int>> cols{{0}};
  for (int p = 1; p <= std::min(3, search.layout.static_powers); ++p) {
    cols.push_back(cols.back());
    cols.back().push_back(search.layout.StaticColumn(0, p));
  }
  std::vector<Eigen::VectorXd> fold_scores;
  std::vector<bool> supported;
  size_t best = 0;
  for (size_t p = 0; p < cols.size(); ++p) {
    fold_scores.push_back(scores.Scores(cols[p]));
    supported.push_back(p == 0 || search.steady.Holds(scores.FullWeights(cols[p]), cols[p]));
    if (supported[p] && scores.Mean(fold_scores[p]) < scores.Mean(fold_scores[best])) best = p;
  }
  size_t degree = best;
  for (size_t p = 0; p < best; ++p) {
    if (!supported[p]) continue;
    const Eigen::VectorXd d = fold_scores[p] - fold_scores[best];
    if (scores.Mean(d) <= standard_errors * scores.StandardError(d)) {
      degree = p;
      break;
    }
  }
  const Eigen::VectorXd gain = fold_scores[degree] - fold_scores[0];
  if (degree > 0 && !(scores.Mean(gain) < -standard_errors * scores.StandardError(gain))) {
    degree = 0;
  }
  AutopilotForm& form = model.autopilot;
  form.degree = static_cast<int>(degree);
  form.tmin_c = temperature_c.minCoeff();
  form.tmax_c = temperature_c.maxCoeff();
  form.tref_c = 0.5 * (form.tmin_c + form.tmax_c);
  const double half = std::max(0.5 * (form.tmax_c - form.tmin_c), 1e-12);
  const auto rows = static_cast<Eigen::Index>(weight.sum());
  Eigen::MatrixXd x(rows, form.degree + 1);
  Eigen::VectorXd ys(rows);
  for (Eigen::Index i = 0, r = 0; i < y.size(); ++i) {
    if (weight[i] <= 0.0) continue;
    const double u = (temperature_c[i] - form.tref_c) / half;
    for (int k = 0; k <= form.degree; ++k) x(r, k) = k == 0 ? 1.0 : x(r, k - 1) * u;
    ys[r++] = y[i];
  }
  const Eigen::VectorXd a = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(x).solve(ys);
  for (int k = 0; k <= form.degree; ++k) form.coefficients[k] = a[k] / std::pow(half, k);
  const double removed = slow.constant_ms - slow.chosen_ms;
  form.share_kept = std::isnan(model.report.skill) || !(removed > 0.0)
                        ? std::numeric_limits<double>::quiet_NaN()
                        : (slow.constant_ms - slow_ms(cols[degree])) / removed;
}

// The nonlinear correction (header comment) on the chosen structure's residual. The network
// sees every regressor of the model but the intercept (a rate that did not enter included: the
// model's columns are what Estimate hands it).
void AddCorrection(const Eigen::VectorXd& residual, std::uint64_t seed, const Search& search,
                   ThermalRegression& model) {
  const internal::Subset& best = search.result.chosen;
  const internal::DesignLayout& layout = search.layout;
  std::vector<int> model_cols;
  for (int c = 0; c < model.channels(); ++c) {
    for (int q = 1; q <= best.static_power; ++q) model_cols.push_back(layout.StaticColumn(c, q));
  }
  for (int j : best.states) {
    for (int q = 0; q <= model.max_power; ++q) model_cols.push_back(layout.StateColumn(j, q));
  }
  if (best.hysteresis_state >= 0) {
    model_cols.push_back(layout.WidthColumn(
        best.states[static_cast<size_t>(best.hysteresis_state)], best.hysteresis_width));
  }
  model.correction =
      FitCorrection(*search.scores, search.x(Eigen::all, best.cols),
                    search.x(Eigen::all, model_cols), search.yc, best, residual, seed, model.report);
}

}  // namespace

ThermalRegression IdentifyThermalModel(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                       const Eigen::Ref<const Eigen::VectorXd>& y_given,
                                       double rate_hz, const ThermalModelOptions& options,
                                       const ThermalIdentification& run) {
  const Eigen::VectorXd weight = CheckedWeights(temperatures_c, y_given, rate_hz, options, run);
  // The target with its made-up samples at 0, so that no product over every row reads them.
  const Eigen::VectorXd y = (weight.array() > 0.0).select(y_given.array(), 0.0).matrix();
  ThermalRegression model;
  model.rate_hz = rate_hz;
  model.order = options.state_order;
  model.max_power = options.max_power;
  for (int c = 0; c < temperatures_c.cols(); ++c) {
    model.centre_c.push_back(temperatures_c.col(c).mean());
    model.scale_k.push_back(Sd(temperatures_c.col(c)));
  }
  Search search;
  ChooseStructure(temperatures_c, y, weight, options, run, model, search);
  ReportHeldOut(search, model.report);
  Eigen::MatrixXd gram;
  const Eigen::VectorXd residual = RefitChosen(y, weight, search, model, gram);
  const SlowError slow_ms(residual, weight, search, rate_hz);
  const SlowParts slow = SlowErrorAndSkill(slow_ms, search, model);
  FitAutopilotForm(temperatures_c.col(0), y, weight, search, options.standard_errors, slow_ms,
                   slow, model);
  if (run.nonlinear && search.result.chosen.cols.size() > 1) {
    AddCorrection(residual, run.seed, search, model);
  }
  const Eigen::VectorXd unit = gram.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                 unit.asDiagonal() * gram * unit.asDiagonal())
                                 .eigenvalues();
  model.report.condition =
      ev[0] > 0.0 ? ev[ev.size() - 1] / ev[0] : std::numeric_limits<double>::infinity();
  internal::AddWarnings(model, options, search.result, search.regimes, model.report);
  model.Validate();
  return model;
}

}  // namespace gyrodrift::drift
