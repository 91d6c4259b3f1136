#include "gyrodrift/drift/thermal_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

#include "../common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/features.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::drift {
namespace {

constexpr double kRateSmoothingS = 60.0;  // smoothing of the rate that tells ramps from dwells
constexpr double kShortestSegmentS = 300.0;
constexpr double kShortestDwellS = 600.0;
constexpr double kBlockS = 600.0;            // blocks of the residual's batch means
constexpr double kShortBlockS = 10.0;        // blocks that measure the residual's fast noise
// Calibration sufficiency: warnings below these (docs/drift.md 4.5).
constexpr double kShortestSpanK = 15.0;
constexpr double kLeastSkill = 0.2;
constexpr double kLargestCondition = 1e10;
// A coil lags its case sensor by up to about an hour (our simulator: 40 min; the family's layer
// chains: 10-60 min): a run whose slowest candidate state lags less cannot identify such a gyro.
constexpr double kSlowLagS = 1800.0;
constexpr Eigen::Index kShortestFold = 16;   // samples
constexpr double kRelativeRidge = 1e-10;     // on the unit-diagonal Gram of a subset
// Candidates of the nonlinear correction (hidden units ascending: they share one hidden layer).
constexpr std::array<int, 4> kCorrectionUnits{5, 10, 20, 40};
constexpr std::array<double, 4> kCorrectionRidge{1e-2, 1.0, 1e2, 1e4};
constexpr size_t kMostHysteresisWidths = 8;

constexpr internal::EnumNames<HysteresisTerm, 3> kHysteresisTerms{{
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

// Columns of one state: its standardised level to the powers 1..max_power (the powers >= 2
// continued along their tangent beyond [s.level_min, s.level_max]), its rate (K/s), then H_w of
// its level for each of widths_k. With `learn_range` the range is first set to the level's own
// (the calibration run). `level` receives the state's level (degC).
void StateColumns(const Eigen::Ref<const Eigen::VectorXd>& t, ThermalState& s, int order,
                  int max_power, double dt_s, double centre, double scale, bool learn_range,
                  const std::vector<Eigen::Index>& record_starts,
                  const std::vector<double>& widths_k, Eigen::Ref<Eigen::MatrixXd> out,
                  Eigen::VectorXd& state) {
  Eigen::VectorXd previous;
  StateOf(t, s.tau_s, order, dt_s, record_starts, previous, state);
  const Eigen::ArrayXd z = (state.array() - centre) / scale;
  if (learn_range) {
    s.level_min = z.minCoeff();
    s.level_max = z.maxCoeff();
  }
  out.col(0) = z.matrix();
  for (int p = 2; p <= max_power; ++p) {
    auto col = out.col(p - 1);
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      const double edge = std::clamp(z[i], s.level_min, s.level_max);
      col[i] = std::pow(edge, p) + p * std::pow(edge, p - 1) * (z[i] - edge);
    }
  }
  out.col(max_power) = (previous - state) / s.tau_s;
  HysteresisColumns(state, widths_k, record_starts,
                    out.middleCols(max_power + 1, static_cast<Eigen::Index>(widths_k.size())));
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

// Least squares on the columns `cols` of Gram G and moment b, solved with unit-diagonal scaling
// and a tiny ridge (the subsets' columns can be close to collinear).
Eigen::VectorXd SolveSubset(const Eigen::MatrixXd& g, const Eigen::VectorXd& b,
                            const std::vector<int>& cols) {
  const Eigen::Index m = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd a(m, m);
  Eigen::VectorXd rhs(m), d(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    d[i] = 1.0 / std::sqrt(std::max(g(cols[i], cols[i]), std::numeric_limits<double>::min()));
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    rhs[i] = b[cols[i]] * d[i];
    for (Eigen::Index j = 0; j < m; ++j) a(i, j) = g(cols[i], cols[j]) * d[i] * d[j];
    a(i, i) += kRelativeRidge;
  }
  Eigen::VectorXd w = a.ldlt().solve(rhs);
  return w.cwiseProduct(d);
}

// Mean of squares of the block means of x over blocks of `block` samples.
double BlockMeanSquare(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block) {
  const Eigen::Index blocks = x.size() / block;
  if (blocks == 0) return x.mean() * x.mean();
  double sum = 0.0;
  for (Eigen::Index i = 0; i < blocks; ++i) {
    const double m = x.segment(i * block, block).mean();
    sum += m * m;
  }
  return sum / static_cast<double>(blocks);
}

// printf-style formatting for the report's texts (the core library has no fmt dependency).
std::string Format(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

// ---- identification, step by step ------------------------------------------------------------

// Span of every channel, heating and cooling rates, ramps and dwells (channel 0 for the latter).
void DescribeRun(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c, double rate_hz,
                 const std::vector<ThermalSegment>& segments,
                 const std::vector<Eigen::Index>& record_starts, CalibrationReport& report) {
  const double dt = 1.0 / rate_hz;
  for (Eigen::Index c = 0; c < temperatures_c.cols(); ++c) {
    report.span_k.push_back(temperatures_c.col(c).maxCoeff() - temperatures_c.col(c).minCoeff());
  }
  for (const ThermalSegment& s : segments) {
    if (s.ramp) {
      ++report.ramps;
    } else if (static_cast<double>(s.end - s.begin) * dt >= kShortestDwellS) {
      ++report.dwells;
    }
  }
  ForEachRecord(temperatures_c.rows(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
    const auto t = temperatures_c.col(0).segment(begin, length);
    Eigen::VectorXd smooth(length);
    FirstOrderLag(t, kRateSmoothingS, dt, smooth);
    const Eigen::VectorXd rate = (t - smooth) * (60.0 / kRateSmoothingS);
    report.max_heating_k_per_min = std::max(report.max_heating_k_per_min, rate.maxCoeff());
    report.max_cooling_k_per_min = std::max(report.max_cooling_k_per_min, -rate.minCoeff());
  });
}

// Ramps and dwells of every record, one after the other (a regime never spans two records).
std::vector<ThermalSegment> RecordSegments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                           double rate_hz, double ramp_rate_k_per_min,
                                           const std::vector<Eigen::Index>& record_starts) {
  std::vector<ThermalSegment> all;
  ForEachRecord(temperature_c.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
    for (ThermalSegment s : Segments(temperature_c.segment(begin, length), rate_hz,
                                     ramp_rate_k_per_min)) {
      s.begin += begin;
      s.end += begin;
      all.push_back(s);
    }
  });
  return all;
}

// Every candidate column: the intercept, the channels' standardised linear terms, then per
// candidate state its powers, its rate and H_w for each of widths_k (each candidate learning its
// level's range).
Eigen::MatrixXd CandidateDesign(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                double rate_hz, const std::vector<Eigen::Index>& record_starts,
                                const ThermalRegression& model,
                                const std::vector<double>& widths_k,
                                std::vector<ThermalState>& candidates) {
  const int channels = static_cast<int>(temperatures_c.cols());
  const int per_state = model.max_power + 1 + static_cast<int>(widths_k.size());
  const Eigen::Index first_state = 1 + channels;
  Eigen::MatrixXd x(temperatures_c.rows(),
                    first_state + static_cast<Eigen::Index>(candidates.size()) * per_state);
  Eigen::VectorXd level;
  x.col(0).setOnes();
  for (int c = 0; c < channels; ++c) {
    x.col(1 + c) = (temperatures_c.col(c).array() - model.centre_c[static_cast<size_t>(c)]) /
                   model.scale_k[static_cast<size_t>(c)];
  }
  for (size_t j = 0; j < candidates.size(); ++j) {
    const auto c = static_cast<size_t>(candidates[j].channel);
    StateColumns(temperatures_c.col(candidates[j].channel), candidates[j], model.order,
                 model.max_power, 1.0 / rate_hz, model.centre_c[c], model.scale_k[c],
                 /*learn_range=*/true, record_starts, widths_k,
                 x.middleCols(first_state + static_cast<Eigen::Index>(j) * per_state, per_state),
                 level);
  }
  return x;
}

// K-fold cross-validation of least squares on column subsets of a design, from moments: per unit
// (time block or regime) Gram matrices summed into each fold's, the training part's being the
// total less the fold's. One pass over the data, then a small solve per subset and fold.
class CrossValidation {
 public:
  struct Fold {
    Eigen::MatrixXd g, g_train;
    Eigen::VectorXd b, b_train;
    double yy = 0.0;
    Eigen::Index begin = 0, end = 0;
  };

  // x: N x M design; yc: the centred target; folds: [first, last) ranges of `units`.
  CrossValidation(const Eigen::MatrixXd& x, const Eigen::VectorXd& yc,
                  const std::vector<ThermalSegment>& units,
                  const std::vector<std::pair<int, int>>& folds)
      : x_(x), yc_(yc) {
    const Eigen::Index m = x.cols();
    std::vector<Eigen::MatrixXd> g(units.size());
    std::vector<Eigen::VectorXd> b(units.size());
    std::vector<double> yy(units.size());
    Eigen::MatrixXd g_total = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd b_total = Eigen::VectorXd::Zero(m);
    for (size_t i = 0; i < units.size(); ++i) {
      const Eigen::Index begin = units[i].begin, length = units[i].end - units[i].begin;
      const auto xu = x.middleRows(begin, length);
      g[i] = Eigen::MatrixXd::Zero(m, m);
      g[i].selfadjointView<Eigen::Lower>().rankUpdate(xu.transpose());
      g[i] = g[i].selfadjointView<Eigen::Lower>();
      b[i] = xu.transpose() * yc.segment(begin, length);
      yy[i] = yc.segment(begin, length).squaredNorm();
      g_total += g[i];
      b_total += b[i];
    }
    for (const auto& [first, last] : folds) {
      Fold f{Eigen::MatrixXd::Zero(m, m), {}, Eigen::VectorXd::Zero(m), {}, 0.0,
             units[static_cast<size_t>(first)].begin, units[static_cast<size_t>(last - 1)].end};
      for (int i = first; i < last; ++i) {
        f.g += g[static_cast<size_t>(i)];
        f.b += b[static_cast<size_t>(i)];
        f.yy += yy[static_cast<size_t>(i)];
      }
      f.g_train = g_total - f.g;
      f.b_train = b_total - f.b;
      folds_.push_back(std::move(f));
    }
  }

  const std::vector<Fold>& folds() const { return folds_; }
  // The training part's least-squares weights of fold f on the columns `cols`.
  Eigen::VectorXd Weights(const Fold& f, const std::vector<int>& cols) const {
    return SolveSubset(f.g_train, f.b_train, cols);
  }

  // Cross-validated mean square error of the columns `cols`.
  double Mse(const std::vector<int>& cols) const {
    double sum = 0.0;
    for (const Fold& f : folds_) {
      const Eigen::VectorXd w = Weights(f, cols);
      double e = f.yy;
      for (size_t i = 0; i < cols.size(); ++i) {
        e -= 2.0 * w[static_cast<Eigen::Index>(i)] * f.b[cols[i]];
        for (size_t j = 0; j < cols.size(); ++j) {
          e += w[static_cast<Eigen::Index>(i)] * f.g(cols[i], cols[j]) *
               w[static_cast<Eigen::Index>(j)];
        }
      }
      sum += std::max(0.0, e);
    }
    return sum / static_cast<double>(yc_.size());
  }

  // Residual of every held-out fold's cross-validated prediction.
  Eigen::VectorXd Residual(const std::vector<int>& cols) const {
    Eigen::VectorXd r(yc_.size());
    for (const Fold& f : folds_) {
      const Eigen::VectorXd w = Weights(f, cols);
      Eigen::MatrixXd xf(f.end - f.begin, static_cast<Eigen::Index>(cols.size()));
      for (size_t i = 0; i < cols.size(); ++i) {
        xf.col(static_cast<Eigen::Index>(i)) = x_.col(cols[i]).segment(f.begin, f.end - f.begin);
      }
      r.segment(f.begin, f.end - f.begin) = yc_.segment(f.begin, f.end - f.begin) - xf * w;
    }
    return r;
  }

 private:
  const Eigen::MatrixXd& x_;
  const Eigen::VectorXd& yc_;
  std::vector<Fold> folds_;
};

// A subset of the candidate design's columns.
struct Subset {
  std::vector<int> cols{0};  // the intercept first
  std::vector<int> states;   // candidate indices
  bool linear = false;       // the channels' linear terms
  int hysteresis_state = -1;  // position in `states` of the state whose H_w is the last column
  int hysteresis_width = -1;  // index of w in the widths tried
  double mse = std::numeric_limits<double>::infinity();
};

// Every subset of at most max_states candidates (combinations in increasing order), with or
// without the channels' linear terms, the intercept alone included, each also with H_w of each
// of its states for each of `widths` widths: the one of least cross-validated error. A
// candidate's block of columns holds state_columns (powers and rate), then its widths.
Subset BestSubset(const CrossValidation& cv, int channels, int candidates, int state_columns,
                  int widths, int max_states) {
  max_states = std::min(max_states, candidates);
  const int per_state = state_columns + widths;
  Subset best;
  std::vector<int> chosen;
  auto visit = [&](auto&& self, int next) -> void {
    for (bool with_linear : {false, true}) {
      Subset s;
      s.states = chosen;
      s.linear = with_linear;
      if (with_linear) {
        for (int c = 0; c < channels; ++c) s.cols.push_back(1 + c);
      }
      for (int j : chosen) {
        for (int p = 0; p < state_columns; ++p) {
          s.cols.push_back(1 + channels + j * per_state + p);
        }
      }
      s.mse = cv.Mse(s.cols);
      for (size_t k = 0; k < chosen.size(); ++k) {
        for (int w = 0; w < widths; ++w) {
          s.cols.push_back(1 + channels + chosen[k] * per_state + state_columns + w);
          const double mse = cv.Mse(s.cols);
          if (mse < best.mse) {
            best = s;
            best.hysteresis_state = static_cast<int>(k);
            best.hysteresis_width = w;
            best.mse = mse;
          }
          s.cols.pop_back();
        }
      }
      if (s.mse < best.mse) best = std::move(s);
    }
    if (static_cast<int>(chosen.size()) == max_states) return;
    for (int j = next; j < candidates; ++j) {
      chosen.push_back(j);
      self(self, j + 1);
      chosen.pop_back();
    }
  };
  visit(visit, 0);
  return best;
}

// The nonlinear correction of the header comment: its candidates on one shared hidden layer of
// the chosen regressors xs (intercept left out), scored against each fold's linear fit on the
// same folds. Null when none lowers the cross-validated error; the report says what was tried.
std::shared_ptr<const Learner> FitCorrection(const CrossValidation& cv, const Eigen::MatrixXd& xs,
                                             const Eigen::VectorXd& yc, const Subset& subset,
                                             const Eigen::VectorXd& residual, std::uint64_t seed,
                                             CalibrationReport& report) {
  const Eigen::Index n = xs.rows();
  const Eigen::MatrixXd z = xs.rightCols(xs.cols() - 1);
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
  for (const CrossValidation::Fold& f : cv.folds()) {
    const Eigen::VectorXd r = yc - xs * cv.Weights(f, subset.cols);
    const Eigen::Index len = f.end - f.begin;
    const auto r_fold = r.segment(f.begin, len);
    // The network's target: the training part's residual, standardised as elm::Fit does.
    const double mean = (r.sum() - r_fold.sum()) / static_cast<double>(n - len);
    const double sd = std::sqrt(std::max(
        ((r.array() - mean).square().sum() - (r_fold.array() - mean).square().sum()) /
            static_cast<double>(n - len),
        std::numeric_limits<double>::min()));
    const Eigen::VectorXd t = (r.array() - mean) / sd;
    const auto h_fold = h.middleRows(f.begin, len);
    const Eigen::MatrixXd hth_train = hth - h_fold.transpose() * h_fold;
    const Eigen::VectorXd ht_train =
        h.transpose() * t - h_fold.transpose() * t.segment(f.begin, len);
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

// What the run cannot identify (docs/drift.md 4.5, "Calibration sufficiency").
void AddWarnings(const ThermalRegression& model, const ThermalModelOptions& options,
                 CalibrationReport& report) {
  auto& w = report.warnings;
  const int channels = model.channels();
  for (int c = 0; c < channels; ++c) {
    if (report.span_k[static_cast<size_t>(c)] < kShortestSpanK) {
      w.push_back(Format("temperature %sspans only %.3g K: the model is not identified beyond it",
                         channels > 1 ? Format("T%d ", c + 1).c_str() : "",
                         report.span_k[static_cast<size_t>(c)]));
    }
  }
  if (report.max_heating_k_per_min < 2.0 * options.ramp_rate_k_per_min)
    w.push_back("no heating ramp: the response to rising temperature is not identified");
  if (report.max_cooling_k_per_min < 2.0 * options.ramp_rate_k_per_min)
    w.push_back("no cooling ramp: the response to falling temperature is not identified");
  if (report.dwells == 0) {
    w.push_back(
        "no dwell of 10 min or more: the level response cannot be told from the rate response");
  }
  if (report.ramps + report.dwells < 3) {
    w.push_back("fewer than 3 thermal regimes (ramps and dwells): nothing new to hold out");
  }
  // The slowest candidate state's mean delay: order x tau.
  const std::vector<double> grid = options.Grid(report.duration_s);
  const double longest_delay = grid.empty() ? 0.0 : options.state_order * grid.back();
  if (longest_delay < kSlowLagS) {
    w.push_back(Format(
        "thermal states could lag the sensor by at most %.0f s (time constants up to %g of the "
        "run): a gyro whose coil lags its sensor by more needs a longer calibration run",
        longest_delay, options.longest_tau_share));
  }
  double slowest = 0.0;
  for (const ThermalState& s : model.states) slowest = std::max(slowest, s.tau_s);
  if (slowest > 0.0 && report.duration_s < 8.0 * slowest) {
    w.push_back(Format("the run is shorter than 8 times the slowest chosen time constant (%g s)",
                       slowest));
  }
  if (report.skill < kLeastSkill) {
    w.push_back(Format(
        "cross-validation confirms little temperature dependence (skill %.1f %%): the estimate "
        "is close to a constant bias",
        100.0 * report.skill));
  }
  if (report.condition > kLargestCondition) {
    w.push_back(Format("the chosen regressors are nearly collinear (condition %.2g)",
                       report.condition));
  }
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
  return internal::EnumName(term, kHysteresisTerms);
}

HysteresisTerm HysteresisTermFromString(std::string_view name) {
  return internal::EnumFromName(name, "hysteresis", kHysteresisTerms);
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

std::vector<ThermalSegment> Segments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                     double rate_hz, double ramp_rate_k_per_min) {
  const Eigen::Index n = temperature_c.size();
  std::vector<ThermalSegment> segments;
  if (n == 0) return segments;
  Eigen::VectorXd smooth(n);
  FirstOrderLag(temperature_c, kRateSmoothingS, 1.0 / rate_hz, smooth);
  const double threshold = ramp_rate_k_per_min / 60.0 * kRateSmoothingS;  // K of lag
  const Eigen::Index shortest =
      std::max<Eigen::Index>(1, static_cast<Eigen::Index>(kShortestSegmentS * rate_hz));
  for (Eigen::Index t = 0; t < n; ++t) {
    const bool ramp = std::abs(temperature_c[t] - smooth[t]) > threshold;
    if (!segments.empty() && segments.back().ramp == ramp) {
      segments.back().end = t + 1;
    } else {
      segments.push_back({t, t + 1, ramp});
    }
  }
  // Merge short stretches into the one before (the first into the one after), then join
  // neighbours of one kind.
  std::vector<ThermalSegment> merged;
  for (const ThermalSegment& s : segments) {
    if (!merged.empty() && (s.end - s.begin < shortest || merged.back().ramp == s.ramp)) {
      merged.back().end = s.end;
    } else if (!merged.empty() && merged.back().end - merged.back().begin < shortest) {
      merged.back().end = s.end;
      merged.back().ramp = s.ramp;
    } else {
      merged.push_back(s);
    }
  }
  return merged;
}

std::string CalibrationReport::Summary() const {
  std::string span;
  for (size_t c = 0; c < span_k.size(); ++c) span += Format("%s%.3g", c ? "/" : "", span_k[c]);
  return Format(
      "%.3g h%s, span %s K, rates +%.2g/-%.2g K/min, %d ramps, %d dwells, %d folds; "
      "cross-validated RMSE %.4g (constant %.4g), skill %.1f %% of the slow drift, condition "
      "%.2g; hysteresis term %s",
      duration_s / 3600.0, records > 1 ? Format(" in %d records", records).c_str() : "",
      span.c_str(), max_heating_k_per_min, max_cooling_k_per_min, ramps,
      dwells, folds, cv_rmse, cv_rmse_constant, 100.0 * skill, condition,
      hysteresis_tried ? "tried" : "not tried") +
         (std::isnan(cv_rmse_nonlinear)
              ? std::string()
              : nonlinear_units > 0
                    ? Format("; nonlinear correction %d units, C %g (cross-validated RMSE %.4g)",
                             nonlinear_units, nonlinear_ridge_c, cv_rmse_nonlinear)
                    : Format("; no nonlinear correction (best cross-validated RMSE %.4g)",
                             cv_rmse_nonlinear));
}

Eigen::MatrixXd ThermalRegression::Regressors(
    const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
    const std::vector<Eigen::Index>& record_starts) const {
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
    if (!linear[static_cast<size_t>(c)]) continue;
    x.col(col++) = (temperatures_c.col(c).array() - centre_c[static_cast<size_t>(c)]) /
                   scale_k[static_cast<size_t>(c)];
  }
  Eigen::VectorXd level, hysteresis_level;
  for (size_t j = 0; j < states.size(); ++j) {
    ThermalState s = states[j];
    const auto c = static_cast<size_t>(s.channel);
    StateColumns(temperatures_c.col(s.channel), s, order, max_power, 1.0 / rate_hz, centre_c[c],
                 scale_k[c], /*learn_range=*/false, record_starts, {},
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
  auto channel = [&](int c) {
    return static_cast<int>(channel_names.size()) == channels()
               ? channel_names[static_cast<size_t>(c)]
               : Format("T%d", c + 1);
  };
  std::vector<std::string> names{"1"};
  for (int c = 0; c < channels(); ++c) {
    if (linear[static_cast<size_t>(c)]) names.push_back(channel(c));
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
  out.col(1) = ((xv.cwiseProduct(x)).rowwise().sum().array().max(0.0) + cv_slow_sd * cv_slow_sd)
                   .sqrt()
                   .matrix();
  return out;
}

std::string ThermalRegression::Summary() const {
  std::string chosen;
  for (const ThermalState& s : states) {
    chosen += Format("%s%.4g s", chosen.empty() ? "" : ", ", s.tau_s);
    if (channels() > 1) chosen += Format(" (T%d)", s.channel + 1);
  }
  const bool any_linear = std::any_of(linear.begin(), linear.end(), [](bool b) { return b; });
  const std::string hysteresis =
      has_hysteresis()
          ? Format(", hysteresis of the %.4g-s state (play %g K)",
                   states[static_cast<size_t>(hysteresis_state)].tau_s, hysteresis_width_k)
          : std::string();
  return Format("thermal states [%s] of order %d to power %d%s%s, cross-validated RMSE %.4g",
                chosen.empty() ? "none" : chosen.c_str(), order, max_power,
                any_linear ? ", linear in T" : "", hysteresis.c_str(), report.cv_rmse);
}

void ThermalRegression::Validate() const {
  const size_t c = centre_c.size();
  if (c == 0 || scale_k.size() != c || linear.size() != c) {
    throw DataError("thermal model: channel fields of unequal length (or none)");
  }
  for (size_t i = 0; i < c; ++i) {
    if (!std::isfinite(centre_c[i]) || !(scale_k[i] > 0.0) || !std::isfinite(scale_k[i])) {
      throw DataError("thermal model: channel " + std::to_string(i + 1) +
                      " needs a finite centre and a positive scale");
    }
  }
  if (!(rate_hz > 0.0) || order < 1 || order > 4 || max_power < 1 || max_power > 3) {
    throw DataError("thermal model: rate_hz, order or max_power out of range");
  }
  for (const ThermalState& s : states) {
    if (s.channel < 0 || s.channel >= channels() || !(s.tau_s >= 1e-9) ||
        !std::isfinite(s.tau_s) || !(s.level_min <= s.level_max) || !std::isfinite(s.level_min) ||
        !std::isfinite(s.level_max)) {
      throw DataError(
          "thermal model: a state names a channel, time constant or level range out of range");
    }
  }
  if (hysteresis_state < -1 || hysteresis_state >= static_cast<int>(states.size()) ||
      (has_hysteresis() && !(hysteresis_width_k > 0.0 && std::isfinite(hysteresis_width_k)))) {
    throw DataError("thermal model: the hysteresis term names no state or a width out of range");
  }
  const Eigen::Index m = static_cast<Eigen::Index>(
      1 + std::count(linear.begin(), linear.end(), true) +
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
                                       const std::vector<Eigen::Index>& record_starts) {
  options.Validate();
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
  const Eigen::Index n = y.size();
  const int channels = static_cast<int>(temperatures_c.cols());
  if (channels < 1 || temperatures_c.rows() != n) {
    throw DataError("thermal identification needs temperature columns of " + std::to_string(n) +
                    " samples (the target's), got " + std::to_string(temperatures_c.rows()) +
                    " x " + std::to_string(channels));
  }
  RequireFiniteSignal("target", y, 2 * kShortestFold);
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
  const std::vector<ThermalSegment> segments = RecordSegments(
      temperatures_c.col(0), rate_hz, options.ramp_rate_k_per_min, record_starts);
  DescribeRun(temperatures_c, rate_hz, segments, record_starts, report);

  // Folds: contiguous blocks of equal duration, or groups of whole regimes.
  std::vector<ThermalSegment> units = TimeBlocks(n, options.folds);
  if (options.folds_at_regimes && Partition(segments, n, options.folds).size() >= 3) {
    units = segments;
  }
  const std::vector<std::pair<int, int>> folds = Partition(units, n, options.folds);
  if (folds.size() < 2) {
    throw DataError("calibration run of " + std::to_string(n) +
                    " samples is too short to cross-validate a thermal model (at least " +
                    std::to_string(2 * kShortestFold) + " needed)");
  }
  report.folds = static_cast<int>(folds.size());

  // The search over the candidates' subsets. The target is centred: the intercept absorbs the
  // mean, and the moments stay well scaled.
  std::vector<ThermalState> candidates;
  for (int c = 0; c < channels; ++c) {
    for (double tau : options.Grid(report.duration_s)) candidates.push_back({c, tau});
  }
  report.hysteresis_tried = options.TriesHysteresis(report.duration_s);
  const std::vector<double> widths_k =
      report.hysteresis_tried ? options.hysteresis_widths_k : std::vector<double>{};
  const Eigen::MatrixXd x =
      CandidateDesign(temperatures_c, rate_hz, record_starts, model, widths_k, candidates);
  const Eigen::VectorXd yc = y.array() - y.mean();
  const CrossValidation cv(x, yc, units, folds);
  const Subset best =
      BestSubset(cv, channels, static_cast<int>(candidates.size()), options.max_power + 1,
                 static_cast<int>(widths_k.size()), options.max_states);
  model.linear.assign(static_cast<size_t>(channels), best.linear);
  for (int j : best.states) model.states.push_back(candidates[static_cast<size_t>(j)]);
  if (best.hysteresis_state >= 0) {
    model.hysteresis_state = best.hysteresis_state;
    model.hysteresis_width_k = widths_k[static_cast<size_t>(best.hysteresis_width)];
  }

  // Refit the chosen columns on the whole run (QR of the unit-scaled design).
  const Eigen::Index p = static_cast<Eigen::Index>(best.cols.size());
  Eigen::MatrixXd xs(n, p);
  Eigen::VectorXd scale(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    xs.col(i) = x.col(best.cols[static_cast<size_t>(i)]);
    scale[i] = 1.0 / std::max(xs.col(i).norm(), std::numeric_limits<double>::min());
  }
  const Eigen::MatrixXd xn = xs * scale.asDiagonal();
  model.coefficients = scale.asDiagonal() * Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(xn).solve(y);

  // Uncertainty: the residual variance inflated by its correlation (batch means), and the slow
  // part of the cross-validated residual.
  const Eigen::VectorXd residual = y - xs * model.coefficients;
  const double variance =
      residual.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, n - p));
  const Eigen::Index block = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(std::round(kBlockS * rate_hz)), 1, std::max<Eigen::Index>(1, n / 4));
  const Eigen::VectorXd centred = residual.array() - residual.mean();
  const double inflation =
      variance > 0.0
          ? std::max(1.0, static_cast<double>(block) * BlockMeanSquare(centred, block) / variance)
          : 1.0;
  const Eigen::MatrixXd gram = xn.transpose() * xn;
  model.covariance = scale.asDiagonal() * gram.ldlt().solve(Eigen::MatrixXd::Identity(p, p)) *
                     scale.asDiagonal() * (variance * inflation);
  // What the fast noise contributes to a block mean, from the means of 10-s blocks scaled to the
  // block: exact for white noise, and not fooled by the anti-correlated quantization noise that
  // first differences would count as white.
  const Eigen::Index short_block = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(std::round(kShortBlockS * rate_hz)), 1, block);
  const double white_share = BlockMeanSquare(centred, short_block) *
                             static_cast<double>(short_block) / static_cast<double>(block);
  const double slow_ms = std::max(0.0, BlockMeanSquare(cv.Residual(best.cols), block) - white_share);
  model.cv_slow_sd = std::sqrt(slow_ms);

  if (nonlinear && p > 1) {
    model.correction = FitCorrection(cv, xs, yc, best, residual, seed, report);
  }

  report.cv_rmse = std::sqrt(best.mse);
  report.cv_rmse_constant = std::sqrt(cv.Mse({0}));
  // Skill on the slow part: the white noise, which no thermal model explains, would hide it.
  const double constant_slow_ms =
      std::max(0.0, BlockMeanSquare(cv.Residual({0}), block) - white_share);
  report.skill = constant_slow_ms > 0.0 ? 1.0 - slow_ms / constant_slow_ms : 0.0;
  const Eigen::VectorXd unit = gram.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                 unit.asDiagonal() * gram * unit.asDiagonal())
                                 .eigenvalues();
  report.condition =
      ev[0] > 0.0 ? ev[ev.size() - 1] / ev[0] : std::numeric_limits<double>::infinity();
  AddWarnings(model, options, report);
  model.Validate();
  return model;
}

}  // namespace gyrodrift::drift
