// Identification of a gyro's thermal drift model from its calibration run: which thermal states
// of the temperature channel(s) the drift follows, with their time constants, chosen from the
// data by cross-validation that holds out contiguous stretches of whole ramps and dwells.
//
// Model [choice, measured in docs/drift.md section 4.5]. For temperature channels T_c (degC,
// c = 1..C), standardised z_c = (T_c - mean_c) / sd_c over the calibration run, and S chosen
// thermal states s_j = L^q(T_c(j); tau_j) (q cascaded first-order lags of one channel: the
// temperature at some depth of a winding pack, or of a board behind the case),
//   drift(t) = b0 + sum_c a_c z_c(t) + sum_j [ sum_{p=1..P} g_jp zs_j(t)^p + r_j ds_j/dt (t) ]
//              [ + h H_w(s_k)(t) ]
// where zs_j is s_j standardised like its channel and ds_j/dt = (L^(q-1) - L^q)(T; tau_j) / tau_j
// the state's rate (K/s). The levels and their powers carry the stress and static-bias
// curvature (the coating stress follows the coil's mean temperature, the electronics their own),
// the rates the Shupe drift (temperature rates inside the pack), the difference of two levels
// the static gradient; METHOD.md section 1. The intercept b0 is the unit's repeatable bias.
// The optional last term is thermal hysteresis, a bias that differs between heating and cooling
// through the same temperature (coil adhesive and potting relax with a memory of the direction):
// H_w(s) = (s - P_w[s]) / w in [-1, 1], where P_w is the play operator (backlash) of half-width
// w K on the level of one chosen state s_k, the elementary hysteron of the Prandtl-Ishlinskii
// model (Brokate & Sprekels, Hysteresis and Phase Transitions, 1996, ch. 2): +1 after the state
// has risen by 2w, -1 after it has fallen by 2w, held through dwells.
//
// Identification: every candidate state (channel, tau) with tau on a geometric grid
// (shortest_tau_s .. longest_tau_s, taus_per_octave per factor 2, and at most
// longest_tau_share of the run: a slower lag cannot be told from the run's slow noise) gives
// P + 1 columns; every subset of at most max_states candidates, with or without the channels'
// linear terms (the intercept alone included), is scored by K-fold cross-validation over
// contiguous blocks of the run (or groups of whole regimes: Segments below), and the subset of
// least cross-validated error is refitted on the whole run by least squares (QR). Where the
// hysteresis term is tried (HysteresisTerm), each subset is also scored with H_w of each of its
// states for every w in hysteresis_widths_k. The search
// works on per-block Gram matrices, so it costs one pass over the data (O(N M^2), M = all
// candidate columns) plus a small solve per subset and fold.
//
// Beyond the calibration's range the level powers continue linearly (ThermalState).
//
// Uncertainty: each estimate comes with a standard deviation sqrt(s_cv^2 + x' V x): s_cv is the
// slow part of the cross-validated residual (its 10-min block means, less what the fast noise
// contributes to them, measured on 10-s blocks: the drift error a held-out stretch saw), V the
// coefficient covariance of the fit, inflated by the residual's correlation (batch means over
// 10-min blocks), which grows where the temperature leaves the calibration's range.
//
// Nonlinear option: a sigmoid ELM (elm.h) of the chosen regressors fitted to the linear model's
// residual, its hidden units L in {5, 10, 20, 40} and ridge C in {0.01, 1, 100, 10^4} chosen by
// the same folds (each fold's linear fit, then the network on the training part's residual,
// scored on the held-out fold; all candidates share one hidden layer, as the first L units of a
// network are those of any larger one), kept only when it lowers the cross-validated error.
//
// Calibration sufficiency (CalibrationReport): temperature span, heating and cooling rates,
// dwells, regimes, cross-validated skill against the intercept alone, the conditioning of the
// chosen regressors and how far the candidate states can lag, with warnings where the run cannot
// identify the model.
// Cost: O(N (C G (q + P + W)) + N M^2) for G grid constants, W hysteresis widths tried and
// M = 1 + C + C G (P + 1 + W) columns; a 16-h 1 Hz run with one channel takes about 0.3 s
// (bench_drift's BM_ThermalFit).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/learner.h"

namespace gyrodrift::drift {

// Whether the identification tries the hysteresis term H_w (header comment).
enum class HysteresisTerm {
  kAuto,  // for calibration runs of at least kHysteresisAutoMinDurationS
  kOn,    // always
  kOff,   // never
};
std::string_view ToString(HysteresisTerm term);
HysteresisTerm HysteresisTermFromString(std::string_view name);  // "auto", "on", "off"

// kAuto's shortest calibration run, s [choice, measured on the independent gyro family,
// docs/drift.md 4.7]: on 16-h and 12-h calibrations the term lowered the error on the median and
// the worst units; on 8-h ones it fitted slow noise on units without hysteresis and lost more in
// the worst tenth than it won.
inline constexpr double kHysteresisAutoMinDurationS = 12.0 * 3600.0;

struct ThermalModelOptions {
  double shortest_tau_s = 30.0;   // first grid constant, s, in [1, 1e6]
  double longest_tau_s = 7680.0;  // last grid constant, s, in [shortest_tau_s, 1e6]
  int taus_per_octave = 2;        // grid density (constants per factor 2), in [1, 8]
  // Constants longer than this share of the calibration run are not candidates, in (0, 1]: a
  // slower lag is a trend over the run, which its rate random walk imitates (1 h of a 16-h run).
  double longest_tau_share = 0.0625;
  int max_states = 2;  // thermal states per model, in [0, 4]
  int state_order = 2;  // cascaded lags per state, in [1, 4]
  int max_power = 3;    // powers of each state's level, in [1, 3]
  // Cross-validation folds, in [2, 64]: contiguous blocks of equal duration (2 h of a 16-h run),
  // each holding whole ramps and dwells, or, with folds_at_regimes, cut at the regime boundaries
  // nearest to those (measured worse on the family: docs/drift.md 4.5).
  int folds = 8;
  bool folds_at_regimes = false;
  // A sample belongs to a ramp when its 60-s smoothed rate exceeds this, K/min, in (0, 100].
  double ramp_rate_k_per_min = 0.1;
  HysteresisTerm hysteresis = HysteresisTerm::kAuto;
  // Half-widths w of the play operator tried, K, each in (0, 100], at most 8 [choice, docs/drift.md
  // 4.7: a wide play on a slow state acts as one more slow state and imitates the run's slow
  // noise; 8 K failed, 4 K did no better than these on the family].
  std::vector<double> hysteresis_widths_k{0.5, 1.0, 2.0};
  bool operator==(const ThermalModelOptions&) const = default;
  void Validate() const;  // throws OptionError naming the field
  // The candidate constants for a run of `duration_s` seconds.
  std::vector<double> Grid(double duration_s) const;
  // Whether a run of `duration_s` seconds tries the hysteresis term.
  bool TriesHysteresis(double duration_s) const;
};

// One thermal state: `order` cascaded first-order lags of channel `channel` with constant tau_s.
// Its standardised level spanned [level_min, level_max] over the calibration run; beyond that the
// powers >= 2 continue along their tangent at the nearer end (a model does not extrapolate a
// curvature it never saw: a cubic fitted over 40 K, evaluated 20 K beyond, is what made a short
// calibration's estimate absurd; docs/drift.md 4.5).
struct ThermalState {
  int channel = 0;
  double tau_s = 0.0;
  double level_min = 0.0, level_max = 0.0;
  bool operator==(const ThermalState&) const = default;
};

// A contiguous stretch of one thermal regime of the calibration run.
struct ThermalSegment {
  Eigen::Index begin = 0, end = 0;  // samples [begin, end)
  bool ramp = false;                 // |rate| above ramp_rate_k_per_min (else a dwell)
};

// Ramps and dwells of channel 0 (the smoothed rate against the threshold), stretches shorter than
// 5 minutes merged into the one before.
std::vector<ThermalSegment> Segments(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                     double rate_hz, double ramp_rate_k_per_min);

// What the calibration run offers for identification, and what the fit found.
struct CalibrationReport {
  double duration_s = 0.0;                     // of all records
  int records = 1;                             // stretches whose lag states start afresh
  std::vector<double> span_k;                  // max - min per channel
  double max_heating_k_per_min = 0.0;          // of channel 0, 60-s smoothed
  double max_cooling_k_per_min = 0.0;          // positive number
  int ramps = 0, dwells = 0;                   // regimes (dwells of at least 10 min)
  int folds = 0;                               // cross-validation folds used
  double cv_rmse = 0.0;                        // of the chosen model, target units
  double cv_rmse_constant = 0.0;               // of the intercept alone
  // 1 - slow cross-validated error / that of the intercept alone (10-min block means less the
  // white noise's share): how much of the drift the temperature explains on held-out regimes.
  double skill = 0.0;
  double condition = 0.0;                      // of the chosen regressors' scaled Gram matrix
  // Nonlinear option: the correction's hidden units (0 = none kept) and ridge C, and the
  // cross-validated RMSE with it (NaN when not tried).
  int nonlinear_units = 0;
  double nonlinear_ridge_c = 0.0;
  double cv_rmse_nonlinear = std::numeric_limits<double>::quiet_NaN();
  bool hysteresis_tried = false;               // the search tried the hysteresis term
  std::vector<std::string> warnings;           // empty: the run identifies the model
  std::string Summary() const;                 // one line
};

// A fitted thermal drift model (see the header comment).
struct ThermalRegression {
  double rate_hz = 1.0;
  int order = 2, max_power = 3;
  std::vector<double> centre_c, scale_k;  // per channel
  std::vector<bool> linear;               // per channel: z_c is a regressor
  std::vector<ThermalState> states;
  // The hysteresis term H_w(states[hysteresis_state]) with w = hysteresis_width_k, the last
  // coefficient; hysteresis_state = -1: none. The play operator starts at the state's level at
  // each record's first sample (no direction yet).
  int hysteresis_state = -1;
  double hysteresis_width_k = 0.0;
  Eigen::VectorXd coefficients;  // b0, the linear terms, per state its powers and rate, then h
  Eigen::MatrixXd covariance;    // of the coefficients
  double cv_slow_sd = 0.0;       // s_cv above, target units
  // Nonlinear option: an ELM of the regressors but the intercept (columns 1.. of Regressors),
  // added to the linear estimate; null = linear. The standard deviation ignores it.
  std::shared_ptr<const Learner> correction;
  CalibrationReport report;

  int channels() const { return static_cast<int>(centre_c.size()); }
  bool has_hysteresis() const { return hysteresis_state >= 0; }
  // N x coefficients() design of temperatures (N x channels()), the lag states restarting at
  // every record start (see IdentifyThermalModel).
  Eigen::MatrixXd Regressors(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                             const std::vector<Eigen::Index>& record_starts = {}) const;
  // "1", "T1", "L2(T1; 480 s)^2", "d/dt L2(T1; 480 s)", "H(L2(T1; 480 s); 1 K)"; with one name
  // per channel, the channels are named by them ("L2(coil_c; 480 s)").
  std::vector<std::string> RegressorNames(const std::vector<std::string>& channel_names = {}) const;
  Eigen::VectorXd Estimate(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                           const std::vector<Eigen::Index>& record_starts = {}) const;
  // Estimate and its standard deviation (columns 0 and 1).
  Eigen::MatrixXd EstimateWithSd(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                 const std::vector<Eigen::Index>& record_starts = {}) const;
  std::string Summary() const;  // the chosen states and the cross-validated error
  void Validate() const;        // throws DataError when the stored fields do not fit together

 private:
  Eigen::VectorXd EstimateOf(const Eigen::Ref<const Eigen::MatrixXd>& regressors) const;
};

// Identifies the model of y (N) from temperatures (N x C, degC) sampled at rate_hz; with
// `nonlinear`, also tries the correction above (its hidden weights drawn from a seed derived from
// `seed` through the named stream "thermal-correction").
// Several records (calibration runs, or one log split at its gaps) are given one after the other,
// with record_starts the first sample of every record after the first (CheckRecordStarts): the
// lag states restart at each (from the record's first temperature, as at the start of a run), so
// no state runs across the break, and no ramp or dwell spans two records; the regressors of all
// records are fitted together.
// Throws DataError for a record the cross-validation cannot split (fewer than 2 folds of at least
// 16 samples) or non-finite samples; UsageError for bad options.
ThermalRegression IdentifyThermalModel(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                       const Eigen::Ref<const Eigen::VectorXd>& y, double rate_hz,
                                       const ThermalModelOptions& options, bool nonlinear = false,
                                       std::uint64_t seed = 1,
                                       const std::vector<Eigen::Index>& record_starts = {});

}  // namespace gyrodrift::drift
