#include "gyrodrift/drift/thermal_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "../common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/features.h"
#include "gyrodrift/elm/elm.h"
#include "thermal_report.h"
#include "thermal_search.h"

namespace gyrodrift::drift {
namespace {

constexpr double kBlockS = 600.0;            // blocks of the residual's batch means
constexpr double kShortBlockS = 10.0;        // blocks that measure the residual's fast noise
constexpr Eigen::Index kShortestFold = 16;   // logged samples
// Held-out regimes beyond this many are grouped with their neighbours (the search's cost grows
// with the folds).
constexpr int kMostRegimeFolds = 24;
// The range ends held out: the top and the bottom fifth of channel 0's span.
constexpr double kRangeEndShare = 0.2;
// The skill needs this many 10-min blocks of residual to tell slow error from noise.
constexpr int kLeastSkillBlocks = 4;
// Candidates of the nonlinear correction (hidden units ascending: they share one hidden layer).
constexpr std::array<int, 4> kCorrectionUnits{5, 10, 20, 40};
constexpr std::array<double, 4> kCorrectionRidge{1e-2, 1.0, 1e2, 1e4};
constexpr size_t kMostHysteresisWidths = 8;

constexpr gyrodrift::internal::EnumNames<HysteresisTerm, 3> kHysteresisTerms{{
    {HysteresisTerm::kAuto, "auto"}, {HysteresisTerm::kOn, "on"}, {HysteresisTerm::kOff, "off"}}};

// Standard deviation about the mean (population).
double Sd(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return std::sqrt((x.array() - x.mean()).square().mean());
}

// The state of `order` cascaded lags of t (and the lag before the last, for its rate), every
// lag restarting at each record's first sample.
void StateOf(const Eigen::Ref<const Eigen::VectorXd>& t, double tau_s, int order, double dt_s,
             const std::vector<Eigen::Index>& record_starts, Eigen::VectorXd& previous,
             Eigen::VectorXd& state) {
  state = t;
  for (int o = 0; o < order; ++o) {
    previous = state;
    ForEachRecord(t.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      FirstOrderLag(previous.segment(begin, length), tau_s, dt_s, state.segment(begin, length));
    });
  }
}

// H_w of a state's level (degC) for each half-width w (K): (s - P_w[s]) / w, the play operator
// P_w starting at the level of each record's first sample.
void HysteresisColumns(const Eigen::Ref<const Eigen::VectorXd>& level,
                       const std::vector<double>& widths_k,
                       const std::vector<Eigen::Index>& record_starts,
                       Eigen::Ref<Eigen::MatrixXd> out) {
  for (size_t w = 0; w < widths_k.size(); ++w) {
    const double width = widths_k[w];
    auto col = out.col(static_cast<Eigen::Index>(w));
    ForEachRecord(level.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      double play = level[begin];
      for (Eigen::Index i = begin; i < begin + length; ++i) {
        play = std::clamp(play, level[i] - width, level[i] + width);
        col[i] = (level[i] - play) / width;
      }
    });
  }
}

// z to the power p, continued along its tangent beyond [lo, hi] for p >= 2.
double TangentPower(double z, int p, double lo, double hi) {
  if (p == 1) return z;
  const double edge = std::clamp(z, lo, hi);
  return std::pow(edge, p) + p * std::pow(edge, p - 1) * (z - edge);
}

// Columns of one state: its standardised level to the powers 1..max_power (the powers >= 2
// continued along their tangent beyond [s.level_min, s.level_max]), its rate (K/s; held within
// [s.rate_min, s.rate_max] with `hold_rate`), then H_w of its level for each of widths_k. With
// `learn_range` the ranges are first set to the state's own (the calibration run). `level`
// receives the state's level (degC).
void StateColumns(const Eigen::Ref<const Eigen::VectorXd>& t, ThermalState& s, int order,
                  int max_power, double dt_s, double centre, double scale, bool learn_range,
                  bool hold_rate, const std::vector<Eigen::Index>& record_starts,
                  const std::vector<double>& widths_k, Eigen::Ref<Eigen::MatrixXd> out,
                  Eigen::VectorXd& state) {
  Eigen::VectorXd previous;
  StateOf(t, s.tau_s, order, dt_s, record_starts, previous, state);
  const Eigen::ArrayXd z = (state.array() - centre) / scale;
  auto rate = out.col(max_power);
  rate = (previous - state) / s.tau_s;
  if (learn_range) {
    s.level_min = z.minCoeff();
    s.level_max = z.maxCoeff();
    s.rate_min = rate.minCoeff();
    s.rate_max = rate.maxCoeff();
  }
  if (hold_rate) rate = rate.cwiseMax(s.rate_min).cwiseMin(s.rate_max);
  out.col(0) = z.matrix();
  for (int p = 2; p <= max_power; ++p) {
    auto col = out.col(p - 1);
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      col[i] = TangentPower(z[i], p, s.level_min, s.level_max);
    }
  }
  HysteresisColumns(state, widths_k, record_starts,
                    out.middleCols(max_power + 1, static_cast<Eigen::Index>(widths_k.size())));
}

// The static powers 1..powers of a channel's standardised level z (tangent beyond [lo, hi]).
void StaticColumns(const Eigen::Ref<const Eigen::VectorXd>& z, int powers, double lo, double hi,
                   Eigen::Ref<Eigen::MatrixXd> out) {
  for (int p = 1; p <= powers; ++p) {
    auto col = out.col(p - 1);
    for (Eigen::Index i = 0; i < z.size(); ++i) col[i] = TangentPower(z[i], p, lo, hi);
  }
}

// A partition of the run into folds: contiguous groups of whole units (regimes or time blocks),
// cut at the unit boundaries nearest to i N / K, i = 1..K-1; each fold a range [first, last) of
// unit indices. Fewer folds when units are few.
std::vector<std::pair<int, int>> Partition(const std::vector<ThermalSegment>& segments,
                                           Eigen::Index n, int k) {
  std::vector<int> cuts{0};
  const int count = static_cast<int>(segments.size());
  for (int i = 1; i < k; ++i) {
    const double ideal = static_cast<double>(n) * i / k;
    int best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int j = 1; j < count; ++j) {
      const double d = std::abs(static_cast<double>(segments[static_cast<size_t>(j)].begin) - ideal);
      if (d < best_distance) {
        best_distance = d;
        best = j;
      }
    }
    if (best > cuts.back()) cuts.push_back(best);
  }
  cuts.push_back(count);
  std::vector<std::pair<int, int>> folds;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) folds.emplace_back(cuts[i], cuts[i + 1]);
  return folds;
}

// Equal time blocks as segments, for a run with too few regimes.
std::vector<ThermalSegment> TimeBlocks(Eigen::Index n, int k) {
  std::vector<ThermalSegment> blocks;
  k = static_cast<int>(std::min<Eigen::Index>(k, n / kShortestFold));
  for (int i = 0; i < k; ++i) blocks.push_back({n * i / k, n * (i + 1) / k, false});
  return blocks;
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
                 /*learn_range=*/true, /*hold_rate=*/false, record_starts, widths_k,
                 x.middleCols(layout.StateColumn(static_cast<int>(j), 0),
                              layout.state_columns + layout.widths),
                 level);
    // The rates' support is their sign: a direction the run showed extrapolates (the Shupe and
    // gradient terms are linear in the rates), one it never showed is held at the edge.
    if (heating) candidates[j].rate_max = std::numeric_limits<double>::infinity();
    if (cooling) candidates[j].rate_min = -std::numeric_limits<double>::infinity();
  }
  return x;
}

// The folds of thermal_model.h: equal time blocks (or groups of whole regimes with
// folds_at_regimes), every regime held out in turn (neighbours grouped beyond kMostRegimeFolds),
// the top and the bottom fifth of channel 0's range. Folds with fewer than kShortestFold logged
// samples, or leaving fewer to train on, are dropped.
std::vector<internal::FoldRows> MakeFolds(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                          const std::vector<ThermalSegment>& segments,
                                          const Eigen::VectorXd& weight,
                                          const ThermalModelOptions& options) {
  using internal::FoldRows;
  const Eigen::Index n = temperature_c.size();
  std::vector<FoldRows> folds;
  std::vector<ThermalSegment> units = TimeBlocks(n, options.folds);
  if (options.folds_at_regimes && Partition(segments, n, options.folds).size() >= 3) {
    units = segments;
  }
  for (const auto& [first, last] : Partition(units, n, options.folds)) {
    folds.push_back({internal::kTimeBlocks,
                     {{units[static_cast<size_t>(first)].begin,
                       units[static_cast<size_t>(last - 1)].end}}});
  }
  if (segments.size() >= 2) {
    for (const auto& [first, last] : Partition(segments, n, kMostRegimeFolds)) {
      folds.push_back({internal::kRegimes,
                       {{segments[static_cast<size_t>(first)].begin,
                         segments[static_cast<size_t>(last - 1)].end}}});
    }
  }
  const double lo = temperature_c.minCoeff(), hi = temperature_c.maxCoeff();
  const double edge = kRangeEndShare * (hi - lo);
  for (bool top : {true, false}) {
    FoldRows f{internal::kRangeEnds, {}};
    for (Eigen::Index i = 0; i < n; ++i) {
      const bool in = top ? temperature_c[i] >= hi - edge : temperature_c[i] <= lo + edge;
      if (!in) continue;
      if (!f.ranges.empty() && f.ranges.back().second == i) {
        f.ranges.back().second = i + 1;
      } else {
        f.ranges.emplace_back(i, i + 1);
      }
    }
    folds.push_back(std::move(f));
  }
  const double total = weight.sum();
  std::vector<FoldRows> kept;
  for (FoldRows& f : folds) {
    double logged = 0.0;
    for (const auto& [begin, end] : f.ranges) logged += weight.segment(begin, end - begin).sum();
    if (logged >= kShortestFold && total - logged >= kShortestFold) kept.push_back(std::move(f));
  }
  return kept;
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

}  // namespace

void ThermalModelOptions::Validate() const {
  RequireInRange("shortest_tau_s", shortest_tau_s, 1.0, 1e6);
  RequireInRange("longest_tau_s", longest_tau_s, shortest_tau_s, 1e6);
  if (taus_per_octave < 1 || taus_per_octave > 8) {
    ThrowOption("taus_per_octave", std::to_string(taus_per_octave), "an integer in [1, 8]");
  }
  if (!(longest_tau_share > 0.0 && longest_tau_share <= 1.0)) {
    ThrowOption("longest_tau_share", FormatValue(longest_tau_share), "in (0, 1]");
  }
  if (max_states < 0 || max_states > 4) {
    ThrowOption("max_states", std::to_string(max_states), "an integer in [0, 4]");
  }
  if (state_order < 1 || state_order > 4) {
    ThrowOption("state_order", std::to_string(state_order), "an integer in [1, 4]");
  }
  if (max_power < 1 || max_power > 3) {
    ThrowOption("max_power", std::to_string(max_power), "an integer in [1, 3]");
  }
  if (folds < 2 || folds > 64) ThrowOption("folds", std::to_string(folds), "an integer in [2, 64]");
  if (!(ramp_rate_k_per_min > 0.0 && ramp_rate_k_per_min <= 100.0)) {
    ThrowOption("ramp_rate_k_per_min", FormatValue(ramp_rate_k_per_min), "in (0, 100]");
  }
  if (hysteresis_widths_k.size() > kMostHysteresisWidths) {
    ThrowOption("hysteresis_widths_k", std::to_string(hysteresis_widths_k.size()) + " widths",
                "at most " + std::to_string(kMostHysteresisWidths));
  }
  for (double w : hysteresis_widths_k) RequireInRange("hysteresis_widths_k", w, 1e-9, 100.0);
  if (hysteresis == HysteresisTerm::kOn && hysteresis_widths_k.empty()) {
    ThrowOption("hysteresis_widths_k", "none", "at least one width with hysteresis 'on'");
  }
  RequireInRange("max_condition", max_condition, 1e2, 1e16);
  RequireInRange("standard_errors", standard_errors, 0.0, 10.0);
}

bool ThermalModelOptions::TriesHysteresis(double duration_s) const {
  if (hysteresis_widths_k.empty()) return false;
  switch (hysteresis) {
    case HysteresisTerm::kOn:
      return true;
    case HysteresisTerm::kOff:
      return false;
    case HysteresisTerm::kAuto:
      break;
  }
  return duration_s >= kHysteresisAutoMinDurationS;
}

std::string_view ToString(HysteresisTerm term) {
  return gyrodrift::internal::EnumName(term, kHysteresisTerms);
}

HysteresisTerm HysteresisTermFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "hysteresis", kHysteresisTerms);
}

std::vector<double> ThermalModelOptions::Grid(double duration_s) const {
  const double longest = std::min(longest_tau_s, longest_tau_share * duration_s);
  std::vector<double> grid;
  for (int k = 0;; ++k) {
    const double tau = shortest_tau_s * std::exp2(static_cast<double>(k) / taus_per_octave);
    if (tau > longest * (1.0 + 1e-12)) break;
    grid.push_back(tau);
  }
  return grid;
}

Eigen::MatrixXd ThermalRegression::Regressors(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  return Regressors(temperatures_c, record_starts, /*within_support=*/true);
}

Eigen::MatrixXd ThermalRegression::Regressors(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts, bool within_support) const {
  if (temperatures_c.cols() != channels()) {
    throw DataError("the thermal model takes " + std::to_string(channels()) +
                    " temperature channel(s), " + std::to_string(temperatures_c.cols()) +
                    " given");
  }
  const Eigen::Index n = temperatures_c.rows();
  for (int c = 0; c < channels(); ++c) {
    RequireFiniteSignal("temperature", temperatures_c.col(c), 1);
  }
  CheckRecordStarts(record_starts, n);
  Eigen::MatrixXd x(n, coefficients.size());
  Eigen::Index col = 0;
  x.col(col++).setOnes();
  for (int c = 0; c < channels(); ++c) {
    const auto cu = static_cast<size_t>(c);
    if (static_power[cu] == 0) continue;
    const Eigen::VectorXd z = (temperatures_c.col(c).array() - centre_c[cu]) / scale_k[cu];
    StaticColumns(z, static_power[cu], static_min[cu], static_max[cu],
                  x.middleCols(col, static_power[cu]));
    col += static_power[cu];
  }
  Eigen::VectorXd level, hysteresis_level;
  for (size_t j = 0; j < states.size(); ++j) {
    ThermalState s = states[j];
    const auto c = static_cast<size_t>(s.channel);
    StateColumns(temperatures_c.col(s.channel), s, order, max_power, 1.0 / rate_hz, centre_c[c],
                 scale_k[c], /*learn_range=*/false, within_support, record_starts, {},
                 x.middleCols(col, max_power + 1), level);
    if (static_cast<int>(j) == hysteresis_state) hysteresis_level.swap(level);
    col += max_power + 1;
  }
  if (has_hysteresis()) {
    HysteresisColumns(hysteresis_level, {hysteresis_width_k}, record_starts, x.middleCols(col, 1));
  }
  return x;
}

std::vector<std::string> ThermalRegression::RegressorNames(
    const std::vector<std::string>& channel_names) const {
  using internal::Format;
  auto channel = [&](int c) {
    return static_cast<int>(channel_names.size()) == channels()
               ? channel_names[static_cast<size_t>(c)]
               : Format("T%d", c + 1);
  };
  std::vector<std::string> names{"1"};
  for (int c = 0; c < channels(); ++c) {
    for (int p = 1; p <= static_power[static_cast<size_t>(c)]; ++p) {
      names.push_back(p == 1 ? channel(c) : Format("%s^%d", channel(c).c_str(), p));
    }
  }
  for (const ThermalState& s : states) {
    const std::string state =
        Format("L%d(%s; %.4g s)", order, channel(s.channel).c_str(), s.tau_s);
    names.push_back(state);
    for (int p = 2; p <= max_power; ++p) names.push_back(Format("%s^%d", state.c_str(), p));
    names.push_back("d/dt " + state);
  }
  if (has_hysteresis()) {
    const ThermalState& s = states[static_cast<size_t>(hysteresis_state)];
    names.push_back(Format("H(L%d(%s; %.4g s); %g K)", order, channel(s.channel).c_str(), s.tau_s,
                           hysteresis_width_k));
  }
  return names;
}

Eigen::VectorXd ThermalRegression::Estimate(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  const Eigen::MatrixXd x = Regressors(temperatures_c, record_starts);
  return EstimateOf(x);
}

Eigen::VectorXd ThermalRegression::EstimateOf(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  Eigen::VectorXd estimate = x * coefficients;
  if (correction) estimate += correction->Predict(x.rightCols(x.cols() - 1));
  return estimate;
}

Eigen::MatrixXd ThermalRegression::EstimateWithSd(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
  const Eigen::MatrixXd x = Regressors(temperatures_c, record_starts);
  Eigen::MatrixXd out(x.rows(), 2);
  out.col(0) = EstimateOf(x);
  const Eigen::MatrixXd xv = x * covariance;
  Eigen::ArrayXd variance =
      (xv.cwiseProduct(x)).rowwise().sum().array().max(0.0) + cv_slow_sd * cv_slow_sd;
  if (!states.empty()) {
    // What holding the rates at the edge of their support left out: the model cannot tell.
    const Eigen::VectorXd unheld =
        (Regressors(temperatures_c, record_starts, /*within_support=*/false) - x) * coefficients;
    variance += unheld.array().square();
  }
  out.col(1) = variance.sqrt().matrix();
  return out;
}

std::string ThermalRegression::Summary() const {
  using internal::Format;
  std::string chosen;
  for (const ThermalState& s : states) {
    chosen += Format("%s%.4g s", chosen.empty() ? "" : ", ", s.tau_s);
    if (channels() > 1) chosen += Format(" (T%d)", s.channel + 1);
  }
  const int powers = *std::max_element(static_power.begin(), static_power.end());
  const std::string in_t = powers == 0   ? std::string()
                           : powers == 1 ? std::string(", linear in T")
                                         : Format(", powers of T to %d", powers);
  const std::string hysteresis =
      has_hysteresis()
          ? Format(", hysteresis of the %.4g-s state (play %g K)",
                   states[static_cast<size_t>(hysteresis_state)].tau_s, hysteresis_width_k)
          : std::string();
  return Format("thermal states [%s] of order %d to power %d%s%s, cross-validated RMSE %.4g",
                chosen.empty() ? "none" : chosen.c_str(), order, max_power, in_t.c_str(),
                hysteresis.c_str(), report.cv_rmse);
}

void ThermalRegression::Validate() const {
  const size_t c = centre_c.size();
  if (c == 0 || scale_k.size() != c || static_power.size() != c || static_min.size() != c ||
      static_max.size() != c) {
    throw DataError("thermal model: channel fields of unequal length (or none)");
  }
  for (size_t i = 0; i < c; ++i) {
    if (!std::isfinite(centre_c[i]) || !(scale_k[i] > 0.0) || !std::isfinite(scale_k[i])) {
      throw DataError("thermal model: channel " + std::to_string(i + 1) +
                      " needs a finite centre and a positive scale");
    }
    if (static_power[i] < 0 || static_power[i] > 3 || !(static_min[i] <= static_max[i]) ||
        (static_power[i] > 1 && !(std::isfinite(static_min[i]) && std::isfinite(static_max[i])))) {
      throw DataError("thermal model: channel " + std::to_string(i + 1) +
                      " needs a static power in [0, 3] and a finite range for powers above 1");
    }
  }
  if (!(rate_hz > 0.0) || order < 1 || order > 4 || max_power < 1 || max_power > 3) {
    throw DataError("thermal model: rate_hz, order or max_power out of range");
  }
  for (const ThermalState& s : states) {
    if (s.channel < 0 || s.channel >= channels() || !(s.tau_s >= 1e-9) ||
        !std::isfinite(s.tau_s) || !(s.level_min <= s.level_max) || !std::isfinite(s.level_min) ||
        !std::isfinite(s.level_max) || !(s.rate_min <= s.rate_max) || std::isnan(s.rate_min) ||
        std::isnan(s.rate_max)) {
      throw DataError(
          "thermal model: a state names a channel, time constant or level range out of range");
    }
  }
  if (hysteresis_state < -1 || hysteresis_state >= static_cast<int>(states.size()) ||
      (has_hysteresis() && !(hysteresis_width_k > 0.0 && std::isfinite(hysteresis_width_k)))) {
    throw DataError("thermal model: the hysteresis term names no state or a width out of range");
  }
  const Eigen::Index m = static_cast<Eigen::Index>(
      1 + std::accumulate(static_power.begin(), static_power.end(), 0) +
      static_cast<long>(states.size()) * (max_power + 1) + (has_hysteresis() ? 1 : 0));
  if (correction && correction->num_inputs() != m - 1) {
    throw DataError("thermal model: the nonlinear correction takes " +
                    std::to_string(correction->num_inputs()) + " inputs, not the " +
                    std::to_string(m - 1) + " regressors");
  }
  if (coefficients.size() != m || covariance.rows() != m || covariance.cols() != m ||
      !coefficients.allFinite() || !covariance.allFinite() || !(cv_slow_sd >= 0.0)) {
    throw DataError("thermal model: " + std::to_string(coefficients.size()) +
                    " coefficients (and covariance) for " + std::to_string(m) +
                    " regressors, or non-finite values");
  }
}

ThermalRegression IdentifyThermalModel(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                       const Eigen::Ref<const Eigen::VectorXd>& y, double rate_hz,
                                       const ThermalModelOptions& options, bool nonlinear,
                                       std::uint64_t seed,
                                       const std::vector<Eigen::Index>& record_starts,
                                       const std::vector<bool>& logged) {
  options.Validate();
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
  const Eigen::Index n = y.size();
  const int channels = static_cast<int>(temperatures_c.cols());
  if (channels < 1 || temperatures_c.rows() != n) {
    throw DataError("thermal identification needs temperature columns of " + std::to_string(n) +
                    " samples (the target's), got " + std::to_string(temperatures_c.rows()) +
                    " x " + std::to_string(channels));
  }
  if (!logged.empty() && static_cast<Eigen::Index>(logged.size()) != n) {
    throw DataError("thermal identification: " + std::to_string(logged.size()) +
                    " logged-sample flags for " + std::to_string(n) + " samples");
  }
  Eigen::VectorXd weight = Eigen::VectorXd::Ones(n);
  for (size_t i = 0; i < logged.size(); ++i) weight[static_cast<Eigen::Index>(i)] = logged[i];
  const double n_logged = weight.sum();
  RequireFiniteSignal("target", y, 2 * kShortestFold);
  if (n_logged < 2 * kShortestFold) {
    throw DataError("calibration run of " + std::to_string(static_cast<long>(n_logged)) +
                    " logged samples is too short to cross-validate a thermal model (at least " +
                    std::to_string(2 * kShortestFold) + " needed)");
  }
  if (nonlinear && n_logged < static_cast<double>(n)) {
    throw UsageError("the nonlinear correction needs every sample logged (no gaps carried)");
  }
  CheckRecordStarts(record_starts, n);
  ThermalRegression model;
  model.rate_hz = rate_hz;
  model.order = options.state_order;
  model.max_power = options.max_power;
  for (int c = 0; c < channels; ++c) {
    const auto t = temperatures_c.col(c);
    RequireFiniteSignal("temperature", t, n);
    RequireVaryingSignal("temperature", t,
                         "a thermal model needs a calibration run whose temperature changes");
    model.centre_c.push_back(t.mean());
    model.scale_k.push_back(Sd(t));
  }
  CalibrationReport& report = model.report;
  report.duration_s = static_cast<double>(n) / rate_hz;
  report.records = static_cast<int>(record_starts.size()) + 1;
  const std::vector<ThermalSegment> segments = internal::RecordSegments(
      temperatures_c.col(0), rate_hz, options.ramp_rate_k_per_min, record_starts);
  internal::DescribeRun(temperatures_c, rate_hz, segments, record_starts, report);

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

  // The search over the candidates' subsets. The target is centred on its logged mean: the
  // intercept absorbs the mean, and the moments stay well scaled.
  std::vector<ThermalState> candidates;
  for (int c = 0; c < channels; ++c) {
    for (double tau : options.Grid(report.duration_s)) candidates.push_back({c, tau});
  }
  report.hysteresis_tried = options.TriesHysteresis(report.duration_s);
  const std::vector<double> widths_k =
      report.hysteresis_tried ? options.hysteresis_widths_k : std::vector<double>{};
  const internal::DesignLayout layout{channels, options.max_power,
                                      static_cast<int>(candidates.size()), options.max_power + 1,
                                      static_cast<int>(widths_k.size())};
  const bool heating = report.max_heating_k_per_min >= 2.0 * options.ramp_rate_k_per_min;
  const bool cooling = report.max_cooling_k_per_min >= 2.0 * options.ramp_rate_k_per_min;
  const Eigen::MatrixXd x = CandidateDesign(temperatures_c, rate_hz, record_starts, model, layout,
                                            widths_k, heating, cooling, candidates);
  const double mean = y.dot(weight) / n_logged;
  const Eigen::VectorXd yc = ((y.array() - mean) * weight.array()).matrix();
  // The choice is scored on the time blocks; the held-out regimes and range ends are reported
  // (scoring or gating on them chose worse models on the family: docs/drift.md 4.8).
  const internal::FoldScores scores(x, yc, weight, folds, 1u << internal::kTimeBlocks);
  const internal::SearchResult search = internal::SearchStructure(
      scores, layout,
      {options.max_states, options.max_condition, options.standard_errors, heating != cooling});
  const internal::Subset& best = search.chosen;
  model.static_power.assign(static_cast<size_t>(channels), best.static_power);
  for (int j : best.states) model.states.push_back(candidates[static_cast<size_t>(j)]);
  if (best.hysteresis_state >= 0) {
    model.hysteresis_state = best.hysteresis_state;
    model.hysteresis_width_k = widths_k[static_cast<size_t>(best.hysteresis_width)];
  }
  report.level = best.level;
  report.best_level = search.best_level;
  report.held_out_rmse = std::sqrt(best.score);
  report.held_out_rmse_constant = std::sqrt(search.constant.score);
  report.held_out_rmse_static = std::sqrt(search.static_cubic.score);
  report.held_out_rmse_best = std::sqrt(search.best_score);
  if (report.regime_folds + report.range_folds > 0) {
    auto regimes = [&](const internal::Subset& subset) {
      const Eigen::VectorXd every = scores.Scores(subset.cols, /*every_fold=*/true);
      const int r = report.regime_folds > 0, e = report.range_folds > 0;
      return std::sqrt((scores.SchemeMean(every, internal::kRegimes) * r +
                        scores.SchemeMean(every, internal::kRangeEnds) * e) /
                       (r + e));
    };
    report.regime_rmse = regimes(best);
    report.regime_rmse_constant = regimes(search.constant);
    report.regime_rmse_static = regimes(search.static_cubic);
  }

  // Refit the chosen columns on the logged samples (QR of the unit-scaled design). A state whose
  // rate did not enter keeps a rate coefficient of 0.
  const Eigen::Index p = static_cast<Eigen::Index>(best.cols.size());
  const Eigen::Index rows = static_cast<Eigen::Index>(n_logged);
  Eigen::MatrixXd xs(rows, p);
  Eigen::VectorXd ys(rows);
  for (Eigen::Index i = 0, r = 0; i < n; ++i) {
    if (weight[i] <= 0.0) continue;
    for (Eigen::Index k = 0; k < p; ++k) xs(r, k) = x(i, best.cols[static_cast<size_t>(k)]);
    ys[r++] = y[i];
  }
  Eigen::VectorXd scale(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    scale[i] = 1.0 / std::max(xs.col(i).norm(), std::numeric_limits<double>::min());
  }
  const Eigen::MatrixXd xn = xs * scale.asDiagonal();
  const Eigen::VectorXd fitted =
      scale.asDiagonal() * Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(xn).solve(ys);
  // Where each fitted column sits among the model's m regressors.
  std::vector<Eigen::Index> slot;
  Eigen::Index m = 0;
  {
    Eigen::Index k = 1 + best.static_power * channels;
    for (Eigen::Index i = 0; i < k; ++i) slot.push_back(i);
    for (size_t j = 0; j < best.states.size(); ++j, k += options.max_power + 1) {
      for (int q = 0; q < options.max_power + (best.rates ? 1 : 0); ++q) slot.push_back(k + q);
    }
    if (best.hysteresis_state >= 0) slot.push_back(k++);
    m = k;
  }
  model.coefficients = Eigen::VectorXd::Zero(m);
  for (Eigen::Index i = 0; i < p; ++i) model.coefficients[slot[static_cast<size_t>(i)]] = fitted[i];

  // Uncertainty: the residual variance inflated by its correlation (batch means), and the slow
  // part of the cross-validated residual. Block means are over the logged samples of each block.
  Eigen::VectorXd residual = Eigen::VectorXd::Zero(n);
  {
    const Eigen::VectorXd r = ys - xs * fitted;
    const double r_mean = r.mean();
    for (Eigen::Index i = 0, k = 0; i < n; ++i) {
      if (weight[i] > 0.0) residual[i] = r[k++] - r_mean;
    }
  }
  const double variance =
      residual.squaredNorm() / std::max(1.0, n_logged - static_cast<double>(p));
  const Eigen::Index block = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(std::round(kBlockS * rate_hz)), 1, std::max<Eigen::Index>(1, n / 4));
  double logged_per_block = 0.0, logged_per_short_block = 0.0;
  const double block_ms = BlockMeanSquare(residual, block, weight, &logged_per_block);
  const double inflation =
      variance > 0.0 ? std::max(1.0, logged_per_block * block_ms / variance) : 1.0;
  const Eigen::MatrixXd gram = xn.transpose() * xn;
  const Eigen::MatrixXd covariance = scale.asDiagonal() *
                                     gram.ldlt().solve(Eigen::MatrixXd::Identity(p, p)) *
                                     scale.asDiagonal() * (variance * inflation);
  model.covariance = Eigen::MatrixXd::Zero(m, m);
  for (Eigen::Index i = 0; i < p; ++i) {
    for (Eigen::Index j = 0; j < p; ++j) {
      model.covariance(slot[static_cast<size_t>(i)], slot[static_cast<size_t>(j)]) = covariance(i, j);
    }
  }
  // What the fast noise contributes to a block mean, from the means of 10-s blocks scaled to the
  // block's logged samples: exact for white noise, and not fooled by the anti-correlated
  // quantization noise that first differences would count as white.
  const Eigen::Index short_block = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(std::round(kShortBlockS * rate_hz)), 1, block);
  const double short_ms = BlockMeanSquare(residual, short_block, weight, &logged_per_short_block);
  const double white_share =
      logged_per_block > 0.0 ? short_ms * logged_per_short_block / logged_per_block : 0.0;
  const double slow_ms =
      std::max(0.0, BlockMeanSquare(scores.TimeResidual(best.cols), block, weight) - white_share);
  model.cv_slow_sd = std::sqrt(slow_ms);

  if (nonlinear && p > 1) {
    // The network sees every regressor of the model but the intercept (a rate that did not
    // enter included: the model's columns are what Estimate hands it).
    std::vector<int> model_cols;
    for (int c = 0; c < channels; ++c) {
      for (int q = 1; q <= best.static_power; ++q) model_cols.push_back(layout.StaticColumn(c, q));
    }
    for (int j : best.states) {
      for (int q = 0; q <= options.max_power; ++q) model_cols.push_back(layout.StateColumn(j, q));
    }
    if (best.hysteresis_state >= 0) {
      model_cols.push_back(layout.WidthColumn(
          best.states[static_cast<size_t>(best.hysteresis_state)], best.hysteresis_width));
    }
    model.correction = FitCorrection(scores, x(Eigen::all, best.cols), x(Eigen::all, model_cols),
                                     yc, best,
                                     residual, seed, report);
  }

  report.cv_rmse = std::sqrt(scores.TimeMse(best.cols));
  report.cv_rmse_constant = std::sqrt(scores.TimeMse({0}));
  // Skill on the slow part: the white noise, which no thermal model explains, would hide it.
  const double constant_slow_ms =
      std::max(0.0, BlockMeanSquare(scores.TimeResidual({0}), block, weight) - white_share);
  if (static_cast<double>(n) < kLeastSkillBlocks * kBlockS * rate_hz) {
    report.skill = std::numeric_limits<double>::quiet_NaN();
  } else {
    report.skill = constant_slow_ms > 0.0 ? 1.0 - slow_ms / constant_slow_ms : 0.0;
  }
  const Eigen::VectorXd unit = gram.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                 unit.asDiagonal() * gram * unit.asDiagonal())
                                 .eigenvalues();
  report.condition =
      ev[0] > 0.0 ? ev[ev.size() - 1] / ev[0] : std::numeric_limits<double>::infinity();
  internal::AddWarnings(model, options, search.fell_back_to_constant, report);
  model.Validate();
  return model;
}

}  // namespace gyrodrift::drift
