// Identification of a gyro's thermal drift model from its calibration run: which thermal states
// of the temperature channel(s) the drift follows, with their time constants, and how rich a model
// the run supports, chosen from the data by cross-validation on held-out time blocks and held-out
// thermal regimes.
//
// Model [choice, measured in docs/drift.md section 4.5]. For temperature channels T_c (degC,
// c = 1..C), standardised z_c = (T_c - mean_c) / sd_c over the calibration run, and S chosen
// thermal states s_j = L^q(T_c(j); tau_j) (q cascaded first-order lags of one channel: the
// temperature at some depth of a winding pack, or of a board behind the case),
//   drift(t) = b0 + sum_c sum_{p=1..Q} a_cp z_c(t)^p
//              + sum_j [ sum_{p=1..P} g_jp zs_j(t)^p + r_j ds_j/dt (t) ]  [ + h H_w(s_k)(t) ]
// where zs_j is s_j standardised like its channel and ds_j/dt = (L^(q-1) - L^q)(T; tau_j) / tau_j
// the state's rate (K/s). The static powers (Q <= 3) are the classic polynomial in T; the levels
// and their powers carry the stress and static-bias curvature (the coating stress follows the
// coil's mean temperature, the electronics their own), the rates the Shupe drift (temperature
// rates inside the pack), the difference of two levels the static gradient; METHOD.md section 1.
// The intercept b0 is the unit's repeatable bias. The optional last term is thermal hysteresis, a
// bias that differs between heating and cooling through the same temperature (coil adhesive and
// potting relax with a memory of the direction): H_w(s) = (s - P_w[s]) / w in [-1, 1], where P_w
// is the play operator (backlash) of half-width w K on the level of one chosen state s_k, the
// elementary hysteron of the Prandtl-Ishlinskii model (Brokate & Sprekels, Hysteresis and Phase
// Transitions, 1996, ch. 2): +1 after the state has risen by 2w, -1 after it has fallen by 2w.
//
// Structure: nested models from simple to rich, (0) the constant, (1) static powers of T,
// (2) the powers of one lag state's level, (3) with its rate, (4) two lag states with their rates,
// (5) a hysteresis term (a state without its rate term has a rate coefficient of exactly 0).
// Within each level the subset of least cross-validated error wins; across levels the simplest
// whose error is within one standard error of the best level's and that beats the constant by a
// standard error stands (the one-standard-error rule on the paired scores of the held-out time
// blocks); the constant when the best level does not beat it by a standard error
// (thermal_search.h, ChooseLevel). Every thermal regime (ramp or dwell) held out in turn, and the
// top and the bottom fifth of the temperature range held out, are scored and reported beside
// (choosing or gating on them chose worse models on the family's one-way heat-ups:
// docs/drift.md 4.8). Columns that are nearly collinear (condition of the scaled Gram above
// max_condition: two states of close time constants) never enter together, nor does a subset
// whose steady-state drift across the calibrated range leaves the band of the run's 10-min means
// widened by its width (two plateaus leave a cubic free between them; docs/drift.md 4.10), and
// every level (static or lagged) enters linearly when the run spent less than 30 min in the middle
// half of its temperature range (a step between two holds: docs/drift.md 4.11). A run of holds
// (no ramp, and no record spanning 15 K: plateaus logged apart) takes no lag state: a state is
// its temperature there, and what it would add is a sensor's settling (4.11). A run
// that showed one direction of temperature change or none (no cooling ramp, or no heating ramp)
// takes no lag difference (two states, or a state beside the static term: its sign follows the
// direction) and no hysteresis term.
//
// Support: the model keeps the calibration's range of every static level, state level and state
// rate. Beyond a level's range its powers >= 2 continue along their tangent (a model does not
// extrapolate a curvature it never saw). A rate extrapolates linearly in a direction the run
// showed (a heating or cooling ramp: the Shupe and gradient terms are linear in rates); beyond
// the edge of one it never showed (a run that only heated says nothing of cooling) it moves at
// half its slope (ThermalState::rate_beyond), midway between no response and the mirrored one;
// the estimate's standard deviation grows by what that leaves out either way.
//
// Uncertainty: each estimate comes with a standard deviation sqrt(s_cv^2 + x' V x + e^2): s_cv is
// the slow part of the cross-validated residual (its 10-min block means, less what the fast noise
// contributes to them, measured on 10-s blocks), V the coefficient covariance of the fit, inflated
// by the residual's correlation (batch means over 10-min blocks), e what holding the rates at the
// edge of their support changed.
//
// Nonlinear option: a sigmoid ELM (elm.h) of the chosen regressors fitted to the linear model's
// residual, its hidden units L in {5, 10, 20, 40} and ridge C in {0.01, 1, 100, 10^4} chosen by
// the time-block folds, kept only when it lowers the cross-validated error.
//
// Calibration sufficiency (CalibrationReport): temperature span, heating and cooling rates,
// dwells, regimes, cross-validated skill against the constant and the static polynomial, the
// conditioning of the chosen regressors and how far the candidate states can lag, with warnings
// where the run cannot identify the model, each saying which regime to add.
// Cost: O(N M^2) for the fold moments (M = 1 + C Q + C G (P + 1 + W) columns for G grid constants
// and W hysteresis widths tried), then a small solve per subset and fold; a 16-h 1 Hz run with one
// channel takes about 0.4 s (bench_drift's BM_ThermalFit).
#pragma once

#include <Eigen/Core>
#include <array>
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
  kAuto,  // for calibration runs of at least kHysteresisAutoMinDurationS of logged samples
  kOn,    // always
  kOff,   // never
};
std::string_view ToString(HysteresisTerm term);
HysteresisTerm HysteresisTermFromString(std::string_view name);  // "auto", "on", "off"

// kAuto's shortest calibration run, s [choice, measured on the independent gyro family,
// docs/drift.md 4.7]: on 16-h and 12-h calibrations the term lowered the error on the median and
// the worst units; on 8-h ones it fitted slow noise on units without hysteresis and lost more in
// the worst tenth than it won. The logged samples count, not the span: on duty-cycled 16-h logs
// (5 s of every 300 s) the term made unit 2 worse than raw (docs/drift.md 4.8).
inline constexpr double kHysteresisAutoMinDurationS = 12.0 * 3600.0;

struct ThermalModelOptions {
  double shortest_tau_s = 30.0;   // first grid constant, s, in [1, 1e6]
  double longest_tau_s = 7680.0;  // last grid constant, s, in [shortest_tau_s, 1e6]
  int taus_per_octave = 2;        // grid density (constants per factor 2), in [1, 8]
  // Constants longer than this share of the calibration run are not candidates, in (0, 1]: a
  // slower lag is a trend over the run, which its rate random walk imitates (1 h of a 16-h run).
  double longest_tau_share = 0.0625;
  // Thermal states per model, in [0, 4] (none for a run of holds: header comment, Structure).
  int max_states = 2;
  int state_order = 2;  // cascaded lags per state, in [1, 4]
  int max_power = 3;    // powers of each level (static and states'), in [1, 3]
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
  // Subsets whose scaled Gram matrix is worse conditioned are not candidates, in [1e2, 1e16]
  // [choice, docs/drift.md 4.8: two lag states of 170 and 240 s with coefficients of +-1.3e5 on
  // a real record had 3.9e9].
  double max_condition = 1e8;
  // The one-standard-error rule's multiple, in [0, 10]: a richer structure (and any structure
  // against the constant) must win by this many standard errors of the paired fold scores
  // [choice, docs/drift.md 4.8].
  double standard_errors = 1.0;
  bool operator==(const ThermalModelOptions&) const = default;
  void Validate() const;  // throws OptionError naming the field
  // The candidate constants for a run of `duration_s` seconds.
  std::vector<double> Grid(double duration_s) const;
  // The shortest run, h, rounded up to 0.01 h, whose Grid holds a state lagging by at least
  // `lag_s` (order x tau): the grid goes in steps, so this is more than lag_s / (order x
  // longest_tau_share) in general.
  double HoursReachingLag(double lag_s) const;
  // Whether a run of `logged_s` seconds of logged samples tries the hysteresis term.
  bool TriesHysteresis(double logged_s) const;
};

// One thermal state: `order` cascaded first-order lags of channel `channel` with constant tau_s.
// Its standardised level spanned [level_min, level_max] over the calibration run; beyond that the
// powers >= 2 continue along their tangent at the nearer end (a model does not extrapolate a
// curvature it never saw: a cubic fitted over 40 K, evaluated 20 K beyond, is what made a short
// calibration's estimate absurd; docs/drift.md 4.5).
// Its rate spanned [rate_min, rate_max] K/s; beyond an edge it moves at rate_beyond times its
// own slope (0: held at the edge, as in model files before format 9).
struct ThermalState {
  int channel = 0;
  double tau_s = 0.0;
  double level_min = 0.0, level_max = 0.0;
  double rate_min = -std::numeric_limits<double>::infinity();
  double rate_max = std::numeric_limits<double>::infinity();
  double rate_beyond = 0.0;
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
  // The structures of the nested ladder (header comment), simplest first.
  // kLag: one lag state's level and its powers, without its rate.
  enum Level { kConstant, kStatic, kLag, kOneState, kTwoStates, kHysteresis };
  double duration_s = 0.0;                     // of all records
  int records = 1;                             // stretches whose lag states start afresh
  std::vector<double> span_k;                  // max - min per channel
  double max_heating_k_per_min = 0.0;          // of channel 0, 60-s smoothed
  double max_cooling_k_per_min = 0.0;          // positive number
  int ramps = 0, dwells = 0;                   // regimes (dwells of at least 10 min)
  int folds = 0;                               // cross-validation folds used
  double cv_rmse = 0.0;                        // of the chosen model, target units
  double cv_rmse_constant = 0.0;               // of the intercept alone
  // Held-out RMSE over the time blocks (each block weighing equally) of the chosen model, the
  // constant and the static polynomial in T of the model's max_power (the cubic unless the run
  // supports a line only): what the choice and the guarantee compare.
  double held_out_rmse = 0.0, held_out_rmse_constant = 0.0, held_out_rmse_static = 0.0;
  double held_out_rmse_best = 0.0;             // of the best level, before the rule
  // The same three on the held-out regimes and range ends (reported, not chosen on; 0: no such
  // fold).
  double regime_rmse = 0.0, regime_rmse_constant = 0.0, regime_rmse_static = 0.0;
  int level = kConstant;                       // of the chosen structure
  int best_level = kConstant;                  // of least held-out error, before the rule
  int regime_folds = 0, range_folds = 0;       // held-out regimes, range ends
  // 1 - slow cross-validated error / that of the intercept alone (10-min block means less the
  // white noise's share): how much of the drift the temperature explains on held-out regimes.
  // NaN when the run is shorter than 4 such blocks (not measured).
  double skill = 0.0;
  double condition = 0.0;                      // of the chosen regressors' scaled Gram matrix
  // The ridge on every coefficient but the intercept, in logged samples at the regressor's mean
  // square (0: none; a log most of whose rows were made up across gaps gets one).
  double prior_samples = 0.0;
  // Nonlinear option: the correction's hidden units (0 = none kept) and ridge C, and the
  // cross-validated RMSE with it (NaN when not tried).
  int nonlinear_units = 0;
  double nonlinear_ridge_c = 0.0;
  double cv_rmse_nonlinear = std::numeric_limits<double>::quiet_NaN();
  bool hysteresis_tried = false;               // the search tried the hysteresis term
  std::vector<std::string> warnings;           // empty: the run identifies the model
  // What the run lacks for identification, as regimes to add ("no cooling: add a ramp down of at
  // least 20 K at 0.5-2 K/min"); empty: nothing.
  std::vector<std::string> advice;
  std::string Summary() const;                 // one line
};

// The form an autopilot runs (PX4's thermal compensation of a gyro: docs/firmware.md, section
// "PX4"): a polynomial of degree at most 3 in dT = clamp(T, tmin_c, tmax_c) - tref_c of the first
// temperature channel, nothing else: no lag, no rate. Fitted to the calibration run itself (not to
// the full model's estimate) on the logged samples, its degree chosen as the structure is: the
// lowest within `standard_errors` of the best on the held-out time blocks, and the constant unless
// a higher degree beats it by as much. tref_c is the middle of the calibrated range, tmin_c and
// tmax_c its ends.
struct AutopilotForm {
  int degree = -1;  // 0..3; -1: not fitted (model files older than format 8)
  double tref_c = 0.0, tmin_c = 0.0, tmax_c = 0.0;
  std::array<double, 4> coefficients{};  // of dT^k, target units per K^k (0 above the degree)
  // Of the slow drift the full model removes on the held-out time blocks (the measure of its
  // skill), the share this form removes; NaN when not measured (a run too short for the skill, or
  // a full model that removes nothing).
  double share_kept = std::numeric_limits<double>::quiet_NaN();

  bool fitted() const { return degree >= 0; }
  double Estimate(double temperature_c) const;  // clamped to [tmin_c, tmax_c]
  // "cubic in (T - 20 degC), T held within [5.2, 34.8] degC: keeps 87.3 % of the slow drift the
  // full model removes (held out)".
  std::string Summary() const;
};

// A fitted thermal drift model (see the header comment).
struct ThermalRegression {
  double rate_hz = 1.0;
  // The options' max_power, or 1 where the run supports no curve (header comment, Structure).
  int order = 2, max_power = 3;
  std::vector<double> centre_c, scale_k;  // per channel
  // Per channel: the highest static power of z_c among the regressors (0: none), and the range
  // of z_c over the calibration run (powers >= 2 continue along their tangent beyond it).
  std::vector<int> static_power;
  std::vector<double> static_min, static_max;
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
  AutopilotForm autopilot;  // fitted beside the model, for an autopilot's parameters

  int channels() const { return static_cast<int>(centre_c.size()); }
  bool has_hysteresis() const { return hysteresis_state >= 0; }
  // N x coefficients() design of temperatures (N x channels()), the lag states restarting at
  // every record start (see IdentifyThermalModel).
  Eigen::MatrixXd Regressors(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                             const std::vector<Eigen::Index>& record_starts = {}) const;
  // Without `within_support`, the rates run free beyond their ranges (what the support rule
  // leaves out).
  Eigen::MatrixXd Regressors(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                             const std::vector<Eigen::Index>& record_starts,
                             bool within_support) const;
  // "1", "T1", "T1^2", "L2(T1; 480 s)^2", "d/dt L2(T1; 480 s)", "H(L2(T1; 480 s); 1 K)"; with one name
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

// How one identification runs, beside its options: the layout of the calibration's samples and
// the optional nonlinear correction.
struct ThermalIdentification {
  // Several records (calibration runs, or one log split at its gaps) are given one after the
  // other, with record_starts the first sample of every record after the first
  // (CheckRecordStarts): the lag states restart at each (from the record's first temperature, as
  // at the start of a run), so no state runs across the break, and no ramp or dwell spans two
  // records; the regressors of all records are fitted together.
  std::vector<Eigen::Index> record_starts = {};
  // Empty, or one flag per sample: false marks a sample made up across a gap of a duty-cycled
  // log (interpolated temperature, so the lag states run across the gap); the fit, the folds and
  // every figure of the report use the logged samples only, and y is not read elsewhere.
  std::vector<bool> logged = {};
  // Also try the correction of the header comment, its hidden weights drawn from a seed derived
  // from `seed` through the named stream "thermal-correction".
  bool nonlinear = false;
  std::uint64_t seed = 1;
};

// Identifies the model of y (N) from temperatures (N x C, degC) sampled at rate_hz
// (thermal_identify.cc). Throws DataError for a record the cross-validation cannot split (fewer
// than 2 folds of at least 16 logged samples) or non-finite samples; UsageError for bad options,
// or the nonlinear option with samples made up.
ThermalRegression IdentifyThermalModel(const Eigen::Ref<const Eigen::MatrixXd>& temperatures_c,
                                       const Eigen::Ref<const Eigen::VectorXd>& y, double rate_hz,
                                       const ThermalModelOptions& options,
                                       const ThermalIdentification& run = {});

}  // namespace gyrodrift::drift
