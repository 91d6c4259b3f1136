// The multi-scale drift model (MS-ELM, Chen & Cui, Signal Processing 128, 2016) and the single-
// model baselines behind the same interface.
//
// MS-ELM: the drift record y is decomposed (BEEMDAN by default, decomposition.h), the IMFs are
// grouped by PDF similarity into noise / mixed / drift sub-series (selection.h), one learner is
// trained per sub-series and the model's output is the sum of the sub-models' outputs. In predict
// mode the noise group, white by the selection's test, is predicted by its training mean unless
// its learner beats that mean by 10 % of its mean-square error on the last validation_fraction of
// the training block (fitted on the rest): a learner on white noise's lags adds noise to the sum.
// Two modes:
//   kPredict    the paper's task: one-step-ahead prediction of y[t] from the sub-series' own
//               lags s_g[t-1..t-p] (optionally with the thermal history at t-1).
//   kCompensate what a navigation computer runs: each sub-series is modelled from the thermal
//               history of the temperature channel(s) only, so the model needs nothing but
//               temperature at run time; compensated output = y - estimate.
// Methods: kMsElm (groups), kEmdElm (one ELM per IMF and one for the residue), kThermal (compensate
// mode only: one identified thermal model of y itself), the single models kElm, kPoly, kSvr,
// kBp trained on y itself (thermal features: features.h; poly uses the classic T and dT/dt), and
// the baselines of baseline.h: the references kNone and kConstant (both modes) and the causal
// filters kPersistence, kTrailingMean, kExpSmoothing, kKalmanLevel, kKalmanTrend (predict mode),
// which read neither a decomposition nor the temperature.
// In compensate mode kThermal, kMsElm and kEmdElm identify a thermal model per sub-series from
// the calibration run (thermal_model.h: states, time constants and terms chosen by blocked
// cross-validation); the fitted intercept keeps the unit's repeatable bias (docs/drift.md 1.2).
// Cost: one decomposition of the training record plus one learner fit per sub-series.
// DriftOptions and CausalOptions are plain values (comparable with ==; a model file stores every
// field of DriftOptions); worker threads and progress are the Execution the fit and the
// prediction take as their last argument, which changes no result.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/drift/baseline.h"
#include "gyrodrift/drift/features.h"
#include "gyrodrift/drift/learner.h"
#include "gyrodrift/drift/thermal_model.h"
#include "gyrodrift/selection/selection.h"

namespace gyrodrift::drift {

enum class Mode { kPredict, kCompensate };
std::string_view ToString(Mode mode);
Mode ModeFromString(std::string_view name);  // "predict", "compensate"

enum class Method {
  kMsElm,
  kElm,
  kEmdElm,
  kPoly,
  kSvr,
  kBp,
  kThermal,
  kPersistence,
  kTrailingMean,
  kExpSmoothing,
  kKalmanLevel,
  kKalmanTrend,
  kNone,
  kConstant,
};
std::string_view ToString(Method method);
// "ms-elm", "elm", "emd-elm", "poly", "svr", "bp", "thermal", "persistence", "trailing-mean",
// "exp-smoothing", "kalman-level", "kalman-trend", "none", "constant"
Method MethodFromString(std::string_view name);
// The methods that run in `mode` (kThermal is compensate-only, the filters kPersistence ..
// kKalmanTrend predict-only), in the order above, without the references kNone and kConstant,
// which Evaluate always scores (ReferenceMethods).
std::vector<Method> AllMethods(Mode mode);
// kNone and kConstant: what every evaluation shows first, so that a method worse than doing
// nothing, or than removing the training mean, shows as such.
std::vector<Method> ReferenceMethods();
bool SupportsMode(Method method, Mode mode);
bool UsesDecomposition(Method method);  // kMsElm, kEmdElm

struct DriftOptions {
  Mode mode = Mode::kPredict;
  Method method = Method::kMsElm;
  decomposition::DecompositionOptions decomposition;  // BEEMDAN defaults
  selection::SelectionOptions selection;              // PDF similarity, L2
  FeatureOptions features;
  // The learner of every sub-model. Its kind follows from `method` (ELM for kMsElm, kEmdElm and
  // kElm); the default ELM is sigmoid with the number of hidden units (<= 50) and the ridge C
  // chosen by leave-one-out error.
  LearnerOptions learner;
  // Predict mode: choose p among lag_candidates on the last validation_fraction of the training
  // record (sub-models fitted on the rest), instead of features.lags. MS-ELM's noise group is
  // judged on the same held-out share (SubModel::mean).
  bool auto_lags = false;
  std::vector<int> lag_candidates{1, 2, 4, 8, 16};
  double validation_fraction = 0.2;  // in [0.05, 0.5]
  // Compensate mode, kThermal, kMsElm and kEmdElm: each sub-model is a thermal model identified
  // from the calibration run (`thermal`), linear in its regressors. false = each may add a
  // nonlinear correction (a sigmoid ELM of its regressors), kept only where the same blocked
  // cross-validation says it helps (thermal_model.h; docs/drift.md 4.5).
  bool linear_compensation = true;
  ThermalModelOptions thermal;  // the identification of those sub-models
  // Compensate mode: unset (default) keeps the fitted intercept, the unit's repeatable bias, which
  // a calibration is expected to remove. A temperature (degC, in [-100, 200]) references the
  // estimate to thermal equilibrium there instead: the model's output for a record that sits at
  // that temperature is subtracted, for users who calibrate the bias separately. (An optional, not
  // a NaN, so that == compares options as values.)
  std::optional<double> reference_c;
  // The fit's one seed: the decomposition's noise draws streams (seed, i), sub-model g's learner
  // (or thermal correction) SeedFor(seed, "sub-model", g), the white-noise level the
  // decomposition's streams (common/random.h); decomposition.seed, learner.seed and
  // selection.monte_carlo.seed are overwritten with these.
  std::uint64_t seed = 1;
  DriftOptions();         // sets the learner defaults described above
  void Validate() const;  // throws UsageError naming the field
  bool operator==(const DriftOptions&) const = default;
  // Compensate mode, or predict mode with features.use_temperature (but for a baseline, which
  // reads no temperature): needs the temperature channel.
  bool uses_temperature() const;
};

// One sub-series and its learner.
struct SubModel {
  std::string name = {};       // "noise", "mixed", "drift", "imf3", "residue", "signal"
  std::vector<int> imfs = {};  // IMF indices (1-based) of the training decomposition it sums
  bool has_residue = false;    // it also holds the residue (and any IMF beyond the last listed)
  // Null for identified compensate-mode sub-models, which have `thermal` instead (and in model
  // files written before identification, the zero function of a noise group).
  std::shared_ptr<const Learner> learner = {};
  std::shared_ptr<const ThermalRegression> thermal = {};
  // Predict mode, MS-ELM's noise group (white by the selection's test): its training mean, which
  // predicts it (learner null) when its learner did not beat that mean on held-out data.
  std::optional<double> mean = {};
  std::shared_ptr<const Baseline> baseline = {};  // a baseline method's one sub-model ("signal")
};

struct DriftModel {
  DriftOptions options;
  int lags = 0;           // p used (predict mode; 1 for a baseline: it needs one sample)
  int training_imfs = 0;  // K of the training decomposition (0 for single models)
  Eigen::Index training_samples = 0;
  std::vector<SubModel> sub_models;
  std::string decomposition_summary;        // report of the training decomposition
  std::string selection_summary;            // report of the grouping (kMsElm)
  std::vector<double> lag_validation_rmse;  // auto_lags: per candidate
  // Range of the training temperature, degC (NaN when the model does not use temperature): a
  // thermal model outside it extrapolates (ShareOutsideRange).
  double temperature_min_c = std::numeric_limits<double>::quiet_NaN();
  double temperature_max_c = std::numeric_limits<double>::quiet_NaN();
  bool uses_temperature() const { return options.uses_temperature(); }
  // Temperature channels the model takes (1 unless identified on several).
  int temperature_channels() const;
  bool identified() const;  // its sub-models are identified thermal models
  int num_inputs() const;   // inputs of each learner (not of identified sub-models)
  std::string Summary() const;  // one line
};

// The feature options a model of these options uses: thermal_set kAuto resolved (kClassic for
// Method::kPoly, kLadder otherwise).
FeatureOptions EffectiveFeatures(const DriftOptions& options);

// Sub-series of a decomposition grouped as the model's sub-models expect: column g is the sum of
// the IMFs (and residue) that belong to sub-model g. IMFs beyond the training count and the
// residue go to the sub-model that holds the residue. Single models: one column, y itself.
Eigen::MatrixXd GroupSeries(const DriftModel& model, const decomposition::Decomposition& d);

// Compensate mode with kThermal, kMsElm or kEmdElm: sub-models identified from the calibration
// run (thermal_model.h).
bool IdentifiesThermalModel(const DriftOptions& options);

// Fits a model on target y (N samples) and, where the mode or options need it, temperature
// (N x C, degC; C > 1 only for identified models; empty otherwise). Several records (calibration
// runs, or a log split at its gaps; features.h CheckRecordStarts) are given one after the other
// with the first sample of each after the first in record_starts: compensate mode with
// Method::kThermal only (IdentifyThermalModel restarts its lag states there), UsageError
// otherwise. Runs on execution.threads workers and reports its progress there: the fraction of
// the whole fit and the step, "decompose" (the grouping included) then "fit sub-models". The model
// is the same bits for any execution. `logged` (features.h CheckLogged; empty = every row): a log
// whose gaps were filled (io::GapPolicy::kCarry); the thermal states run over every row, the fit
// uses the logged rows only (y elsewhere is ignored). Compensate mode with a method without a
// decomposition only (thermal, poly, elm, svr, bp), UsageError otherwise. Throws UsageError /
// DataError.
DriftModel FitDriftModel(const Eigen::Ref<const Eigen::VectorXd>& y,
                         const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                         const DriftOptions& options,
                         const std::vector<Eigen::Index>& record_starts = {},
                         const Execution& execution = {}, const std::vector<bool>& logged = {});

// Share of temperature samples outside [min_c, max_c] (0 when the range is NaN: no temperature),
// e.g. a model's training range: where a thermal model extrapolates.
double ShareOutsideRange(const Eigen::Ref<const Eigen::VectorXd>& temperature_c, double min_c,
                         double max_c);

// Compensate mode: the drift estimate at every sample of a temperature record (N x channels;
// relative to equilibrium at options.reference_c if set). With record_starts, every
// record is estimated on its own, its lags starting in equilibrium at its first temperature.
Eigen::VectorXd EstimateDrift(const DriftModel& model,
                              const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                              const std::vector<Eigen::Index>& record_starts = {});
// The estimate (column 0) and its standard deviation (column 1): identified sub-models' bands
// added in quadrature; NaN for models without one (learners on features).
Eigen::MatrixXd EstimateDriftWithSd(const DriftModel& model,
                                    const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                                    const std::vector<Eigen::Index>& record_starts = {});

// Predict mode from given sub-series (N x G, GroupSeries of some decomposition) and thermal
// features (N x F, or empty): horizon-step-ahead predictions of y[t] for t = first .. first +
// count - 1, each from the origin t - horizon + 1 as PredictAhead makes them (first >= lags +
// horizon - 1, else DataError).
Eigen::VectorXd PredictFromSeries(const DriftModel& model,
                                  const Eigen::Ref<const Eigen::MatrixXd>& series,
                                  const Eigen::Ref<const Eigen::MatrixXd>& thermal,
                                  Eigen::Index first, Eigen::Index count, int horizon = 1);

// How a predict-mode model gets its test-time sub-series.
enum class Protocol {
  kPaper,   // decompose the whole record once (what the literature does; sees the future)
  kCausal,  // for each t, decompose only trailing windows y[t-L .. t-1], L from W down to W/2
            // (H steps ahead: the windows ending at t-H; CausalOptions)
};
std::string_view ToString(Protocol protocol);
Protocol ProtocolFromString(std::string_view name);  // "paper", "causal"

struct CausalOptions {
  // W, samples of the longest trailing window, in [16, 1e6]. Default 2896 [choice, measured]: a
  // window's residue estimates the drift at its end; on 1 Hz FOG records one window's mean error
  // falls from 512 samples to a flat minimum at 2048-4096, and the windows below span 2896 down
  // to 1448 around 2048 (2048 alone until 2026-11-28; docs/drift.md 4.3).
  int window = 2896;
  // Realisations of each window's decomposition (noise-assisted methods), in [0, 100000]; 0 = the
  // model's own. Default 1 [choice, measured for BEEMDAN; EEMD, CEEMDAN, ICEEMDAN want more]: the
  // decompositions are the whole cost of the causal protocol, and the mean over several windows
  // brings the drift group's end closer to the drift than more realisations of one window do
  // (docs/drift.md 4.3; 20 until 2026-11-28, then 10 with one window). With fewer than 3
  // realisations BEEMDAN's ensemble band has no spread, so only mode 1 is noise-assisted.
  int ensemble_size = 1;
  // Share of the window mirrored past its end before the decomposition, in [0, 1]: a window of L
  // samples y[t-L..t-1] is followed by y[t-2], y[t-3], ... (min(round(mirror x L), L - 1)
  // samples), so that the end the sub-models read lies inside the decomposed series instead of at
  // its edge, where the envelopes are extrapolated (the EMD end effect). 0 = the window alone.
  // Default 0.5 [choice, measured: docs/drift.md 4.3].
  double mirror = 0.5;
  // Trailing windows decomposed at each origin, in [1, 16]: n windows from W down to W/2 samples,
  // evenly spaced in log (W 2^(-j/(n-1)), rounded, at least 16), whose group series' ends are
  // averaged. An EMD's end moves with the window's start; the mean of several windows' ends is
  // closer to the drift than one window's with more realisations. Default 6 [choice, measured:
  // docs/drift.md 4.3]; 1 = one window of W.
  int windows = 6;

  // Samples a window of `length` is decomposed as: length + its mirrored tail.
  Eigen::Index DecomposedLength(Eigen::Index length) const;
  // The lengths of the `windows` trailing windows, longest (W) first, without repeats.
  std::vector<Eigen::Index> WindowLengths() const;
  // throws OptionError for a window, ensemble size, mirror or window count out of range
  void Validate() const;
  bool operator==(const CausalOptions&) const = default;
};

// Largest prediction horizon, steps.
inline constexpr int kMaxHorizon = 100000;

// The first sample (0-based) PredictAhead can predict horizon steps ahead: the model's lags, and
// under the causal protocol with a decomposition a 16-sample window, before the origin
// first - horizon + 1. Throws UsageError for a horizon outside [1, kMaxHorizon].
Eigen::Index FirstPredictable(const DriftModel& model, Protocol protocol, int horizon);

// Horizon-step-ahead predictions of y[t] for t = first .. N-1 (N - first entries), each made at
// the origin t - horizon + 1 from the samples before it: the sub-series' lags there, then
// recursively, one step at a time, each sub-model's own predictions in place of the samples after
// the origin. Thermal inputs (models fitted with a temperature) are read from the log at every
// step, as for a temperature programme known in advance. first >= FirstPredictable(model,
// protocol, horizon). horizon = 1 is PredictOneStep.
// Single models need no decomposition and are causal under both protocols.
// The paper protocol's decomposition runs on execution.threads workers; the causal protocol's
// origins run in parallel on them (each window's decomposition on one thread) and report the
// fraction of origins whose windows are decomposed, with the step "causal windows". Nothing
// else is reported.
Eigen::VectorXd PredictAhead(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                             const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                             Eigen::Index first, int horizon, Protocol protocol,
                             const CausalOptions& causal = {}, const Execution& execution = {});

// "" unless, under the causal protocol with `causal`'s windows, some sub-model other than the
// residue's and MS-ELM's noise group sums IMFs a window cannot resolve (a series of L samples,
// the window with its mirrored tail, gives about log2(L) - 1 IMFs): then a one-line note naming
// them. Their content falls into the window's residue, so such a sub-model sees at test time
// another series than the one it was trained on (docs/drift.md 4.3).
std::string CausalWindowNote(const DriftModel& model, const CausalOptions& causal);

// One-step-ahead predictions of y[t] for t = first .. N-1 (first >= lags; the returned vector has
// N - first entries): PredictAhead with horizon 1.
Eigen::VectorXd PredictOneStep(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                               const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                               Eigen::Index first, Protocol protocol,
                               const CausalOptions& causal = {}, const Execution& execution = {});

}  // namespace gyrodrift::drift
