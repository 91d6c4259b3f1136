#include "gyrodrift/drift/drift_model.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include "common/enum_names.h"
#include "drift/internal.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::drift {
namespace {

constexpr std::array<std::pair<Mode, std::string_view>, 2> kModes{{
    {Mode::kPredict, "predict"},
    {Mode::kCompensate, "compensate"},
}};
constexpr std::array<std::pair<Method, std::string_view>, 7> kMethods{{
    {Method::kMsElm, "ms-elm"},
    {Method::kElm, "elm"},
    {Method::kEmdElm, "emd-elm"},
    {Method::kPoly, "poly"},
    {Method::kSvr, "svr"},
    {Method::kBp, "bp"},
    {Method::kThermal, "thermal"},
}};
constexpr std::array<std::pair<Protocol, std::string_view>, 2> kProtocols{{
    {Protocol::kPaper, "paper"},
    {Protocol::kCausal, "causal"},
}};

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;

LearnerKind KindOf(Method method) {
  switch (method) {
    case Method::kPoly:
      return LearnerKind::kPoly;
    case Method::kSvr:
      return LearnerKind::kSvr;
    case Method::kBp:
      return LearnerKind::kBp;
    default:
      return LearnerKind::kElm;
  }
}

void RequireTemperatureFor(const Eigen::Ref<const Eigen::MatrixXd>& temperature_c, Eigen::Index n) {
  if (temperature_c.rows() != n || temperature_c.cols() < 1) {
    throw DataError("temperature has " + std::to_string(temperature_c.rows()) +
                    " samples, the target " + std::to_string(n) + ": they must match");
  }
  for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
    RequireFiniteSignal("temperature", temperature_c.col(c), n);
  }
}

Eigen::MatrixXd ThermalOrEmpty(const DriftModel& model,
                               const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                               Eigen::Index n) {
  if (!model.uses_temperature() || IdentifiesThermalModel(model.options)) {
    return Eigen::MatrixXd(n, 0);
  }
  RequireTemperatureFor(temperature_c, n);
  internal::RequireChannelsFor(model.options, temperature_c.cols());
  return ThermalFeatures(temperature_c.col(0), EffectiveFeatures(model.options));
}

// Rows of inputs of sub-model g for t = first .. first + count - 1 (predict mode).
Eigen::MatrixXd PredictRows(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& s,
                            const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index first,
                            Eigen::Index count) {
  Eigen::MatrixXd x(count, model.lags + thermal.cols());
  x.leftCols(model.lags) = LagRows(s, model.lags, first, count);
  if (thermal.cols() > 0) x.rightCols(thermal.cols()) = thermal.middleRows(first - 1, count);
  return x;
}

// Sub-model g's own random stream (common/random.h: the seed rule).
std::uint64_t SubModelSeed(const DriftOptions& o, size_t g) {
  return SeedFor(o.seed, "sub-model", g);
}

LearnerOptions SubModelLearner(const DriftOptions& o, size_t g) {
  LearnerOptions l = o.learner;
  l.kind = KindOf(o.method);
  l.seed = SubModelSeed(o, g);
  l.threads = o.threads;
  return l;
}

}  // namespace

std::string_view ToString(Mode mode) { return EnumName(mode, kModes); }
Mode ModeFromString(std::string_view name) { return EnumFromName(name, "mode", kModes); }
std::string_view ToString(Method method) { return EnumName(method, kMethods); }
Method MethodFromString(std::string_view name) { return EnumFromName(name, "method", kMethods); }
std::string_view ToString(Protocol protocol) { return EnumName(protocol, kProtocols); }
Protocol ProtocolFromString(std::string_view name) {
  return EnumFromName(name, "protocol", kProtocols);
}

bool SupportsMode(Method method, Mode mode) {
  return method != Method::kThermal || mode == Mode::kCompensate;
}

std::vector<Method> AllMethods(Mode mode) {
  std::vector<Method> all;
  for (const auto& [m, name] : kMethods) {
    if (SupportsMode(m, mode)) all.push_back(m);
  }
  return all;
}

bool IdentifiesThermalModel(const DriftOptions& o) {
  return o.mode == Mode::kCompensate &&
         (o.method == Method::kThermal || UsesDecomposition(o.method));
}

FeatureOptions EffectiveFeatures(const DriftOptions& options) {
  FeatureOptions f = options.features;
  if (f.thermal_set == ThermalSet::kAuto) {
    f.thermal_set = options.method == Method::kPoly ? ThermalSet::kClassic : ThermalSet::kLadder;
  }
  return f;
}

bool UsesDecomposition(Method method) {
  return method == Method::kMsElm || method == Method::kEmdElm;
}

DriftOptions::DriftOptions() {
  learner.elm.hidden_units = 50;
  learner.elm.selection = elm::Selection::kAuto;
}

void DriftOptions::Validate() const {
  decomposition.Validate();
  selection.Validate();
  EffectiveFeatures(*this).Validate();
  if (!std::isnan(reference_c)) RequireInRange("reference_c", reference_c, -100.0, 200.0);
  if (!SupportsMode(method, mode)) {
    ThrowOption("method", std::string(ToString(method)),
                "a method of " + std::string(ToString(mode)) +
                    " mode (thermal identifies a compensation model: mode = compensate)");
  }
  thermal.Validate();
  LearnerOptions l = learner;
  l.kind = KindOf(method);
  l.Validate();
  for (int p : lag_candidates) {
    if (p < 1 || p > 256) ThrowOption("lag candidate", std::to_string(p), "an integer in [1, 256]");
  }
  if (auto_lags && lag_candidates.empty()) {
    ThrowOption("lag_candidates", "(empty)", "at least one candidate when lags are 'auto'");
  }
  RequireInRange("validation_fraction", validation_fraction, 0.05, 0.5);
  if (threads < 0 || threads > 1024) {
    ThrowOption("threads", std::to_string(threads), "an integer in [0, 1024] (0 = all cores)");
  }
}

bool DriftOptions::uses_temperature() const {
  return mode == Mode::kCompensate || features.use_temperature;
}

int DriftModel::temperature_channels() const {
  for (const SubModel& sub : sub_models) {
    if (sub.thermal) return sub.thermal->channels();
  }
  return uses_temperature() ? 1 : 0;
}

bool DriftModel::identified() const {
  return std::any_of(sub_models.begin(), sub_models.end(),
                     [](const SubModel& sub) { return sub.thermal != nullptr; });
}

int DriftModel::num_inputs() const {
  const int thermal = uses_temperature() ? EffectiveFeatures(options).NumThermalFeatures() : 0;
  return options.mode == Mode::kCompensate ? thermal : lags + thermal;
}

std::string DriftModel::Summary() const {
  std::string s = std::string(ToString(options.method)) + " (" +
                  std::string(ToString(options.mode)) + "): " + std::to_string(sub_models.size()) +
                  " sub-model" + (sub_models.size() == 1 ? "" : "s") + " [";
  for (size_t g = 0; g < sub_models.size(); ++g) s += (g ? " " : "") + sub_models[g].name;
  s += "], ";
  s += identified()
           ? std::to_string(temperature_channels()) + " temperature channel" +
                 (temperature_channels() == 1 ? "" : "s") + ", identified"
           : std::to_string(num_inputs()) + " inputs";
  if (options.mode == Mode::kPredict) s += ", " + std::to_string(lags) + " lags";
  s += ", trained on " + std::to_string(training_samples) + " samples";
  return s;
}

Eigen::MatrixXd GroupSeries(const DriftModel& model, const decomposition::Decomposition& d) {
  const Eigen::Index n = d.residue.size();
  const int k_total = d.num_imfs();
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(model.sub_models.size()));
  int highest_listed = 0;
  for (const auto& sub : model.sub_models) {
    for (int k : sub.imfs) highest_listed = std::max(highest_listed, k);
  }
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    const SubModel& sub = model.sub_models[g];
    auto col = s.col(static_cast<Eigen::Index>(g));
    for (int k : sub.imfs) {
      if (k <= k_total) col += d.imfs.col(k - 1);
    }
    if (sub.has_residue) {
      for (int k = highest_listed + 1; k <= k_total; ++k) col += d.imfs.col(k - 1);
      col += d.residue;
    }
  }
  return s;
}

namespace internal {

void RequireChannelsFor(const DriftOptions& o, Eigen::Index channels) {
  if (channels <= 1 || IdentifiesThermalModel(o)) return;
  ThrowOption("temperature channels", std::to_string(channels),
              "one for method " + std::string(ToString(o.method)) + " in " +
                  std::string(ToString(o.mode)) +
                  " mode (several channels: compensate mode with thermal, ms-elm or emd-elm)");
}

void RequireHorizon(int horizon) {
  if (horizon < 1 || horizon > kMaxHorizon) {
    ThrowOption("horizon", std::to_string(horizon),
                "an integer in [1, " + std::to_string(kMaxHorizon) + "]");
  }
}

Eigen::Index FirstPredictable(int lags, bool windowed, int horizon) {
  RequireHorizon(horizon);
  constexpr Eigen::Index kShortestWindow = 16;
  const Eigen::Index min_origin = windowed ? std::max<Eigen::Index>(lags, kShortestWindow) : lags;
  return min_origin + horizon - 1;
}

SubSeries PrepareSubSeries(const Eigen::Ref<const Eigen::VectorXd>& y, const DriftOptions& o,
                           bool report) {
  report = report && static_cast<bool>(o.progress);
  SubSeries out;
  out.model.options = o;
  // A model keeps no caller callbacks (it may run later, from other threads, after they are
  // gone) and no shared noise EMDs (they serve one record length; a model predicts on any).
  out.model.options.progress = nullptr;
  out.model.options.decomposition.progress = nullptr;
  out.model.options.decomposition.noise_imf_observer = nullptr;
  out.model.options.decomposition.noise_emds = nullptr;
  if (!UsesDecomposition(o.method)) {
    out.model.sub_models.push_back({"signal", {}, true, nullptr});
    out.series = y;
    return out;
  }
  decomposition::DecompositionOptions dopt = o.decomposition;
  dopt.seed = o.seed;
  dopt.threads = o.threads;
  if (report) {
    o.progress(0.0, "decompose");
    dopt.progress = [&o](double fraction) { o.progress(kDecomposeShare * fraction, "decompose"); };
  }
  decomposition::Decomposition d;
  std::optional<selection::SelectionResult> sel;
  if (o.method == Method::kEmdElm) {
    d = decomposition::Decompose(y, dopt);
  } else {
    selection::SelectionOptions sopt = o.selection;
    sopt.threads = o.threads;
    // The white-noise level, when it cannot reuse the decomposition's noise, draws the same
    // realisations itself: the user's seed, not the Monte-Carlo's default.
    sopt.monte_carlo.seed = o.seed;
    selection::GroupedDecomposition grouped = selection::DecomposeAndSelect(y, dopt, sopt);
    d = std::move(grouped.decomposition);
    sel = std::move(grouped.selection);
  }
  out.model.training_imfs = d.num_imfs();
  out.model.decomposition_summary = d.report.Summary();
  if (d.num_imfs() == 0) {
    out.model.sub_models.push_back({"signal", {}, true, nullptr});
  } else if (o.method == Method::kEmdElm) {
    for (int k = 1; k <= d.num_imfs(); ++k) {
      out.model.sub_models.push_back({"imf" + std::to_string(k), {k}, false, nullptr});
    }
    out.model.sub_models.push_back({"residue", {}, true, nullptr});
  } else {
    out.model.selection_summary = sel->Summary();
    for (const auto& group : sel->groups) {
      out.model.sub_models.push_back(
          {std::string(selection::ToString(group.kind)), group.imfs, group.has_residue, nullptr});
    }
  }
  out.series = GroupSeries(out.model, d);
  return out;
}

void FitLearners(DriftModel& model, const Eigen::Ref<const Eigen::MatrixXd>& series,
                 const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::MatrixXd>& thermal, Eigen::Index fit_end,
                 const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                 const std::vector<Eigen::Index>& record_starts) {
  const DriftOptions& o = model.options;
  model.training_samples = fit_end;
  const size_t groups = model.sub_models.size();
  if (IdentifiesThermalModel(o)) {
    // Every sub-series chooses its own thermal states: fast rate terms for the noise and mixed
    // groups, slow levels for the drift group, if the data say so.
    for (size_t g = 0; g < groups; ++g) {
      model.sub_models[g].thermal = std::make_shared<const ThermalRegression>(
          IdentifyThermalModel(temperature_c.topRows(fit_end),
                               series.col(static_cast<Eigen::Index>(g)).head(fit_end),
                               o.features.rate_hz, o.thermal, !o.linear_compensation,
                               SubModelSeed(o, g), record_starts));
    }
    return;
  }
  if (o.mode == Mode::kCompensate) {  // a single learner on the thermal features
    model.sub_models.front().learner =
        FitLearner(thermal.topRows(fit_end), series.col(0).head(fit_end),
                   SubModelLearner(o, 0));
    return;
  }
  auto fit_with_lags = [&](int p, Eigen::Index end) {
    model.lags = p;
    if (end - p < 8) {
      throw DataError("training block of " + std::to_string(end) + " samples is too short for " +
                      std::to_string(p) + " lags (at least " + std::to_string(p + 8) + " needed)");
    }
    for (size_t g = 0; g < groups; ++g) {
      const auto s = series.col(static_cast<Eigen::Index>(g));
      model.sub_models[g].learner =
          FitLearner(PredictRows(model, s, thermal, p, end - p), s.segment(p, end - p),
                     SubModelLearner(o, g));
    }
  };
  if (!o.auto_lags) {
    fit_with_lags(o.features.lags, fit_end);
    return;
  }
  const Eigen::Index validation =
      static_cast<Eigen::Index>(std::floor(o.validation_fraction * fit_end));
  const Eigen::Index inner_end = fit_end - validation;
  double best = std::numeric_limits<double>::infinity();
  int best_p = o.lag_candidates.front();
  model.lag_validation_rmse.clear();
  for (int p : o.lag_candidates) {
    fit_with_lags(p, inner_end);
    const Eigen::VectorXd pred = PredictFromSeries(model, series, thermal, inner_end, validation);
    const double rmse =
        std::sqrt((pred - y.segment(inner_end, validation)).squaredNorm() / validation);
    model.lag_validation_rmse.push_back(rmse);
    if (rmse < best) {
      best = rmse;
      best_p = p;
    }
  }
  fit_with_lags(best_p, fit_end);
}

}  // namespace internal

DriftModel FitDriftModel(const Eigen::Ref<const Eigen::VectorXd>& y,
                         const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                         const DriftOptions& options,
                         const std::vector<Eigen::Index>& record_starts) {
  options.Validate();
  if (!record_starts.empty() &&
      !(options.mode == Mode::kCompensate && options.method == Method::kThermal)) {
    throw UsageError(
        "several records (calibration logs, or a log split at its gaps) are fitted by method "
        "thermal in compensate mode only: method " + std::string(ToString(options.method)) +
        " in " + std::string(ToString(options.mode)) +
        " mode needs one uniform record (decompositions and lags run across a break)");
  }
  RequireFiniteSignal("target", y, 32);
  CheckRecordStarts(record_starts, y.size());
  RequireVaryingSignal("target", y, "there is nothing to model");
  if (options.uses_temperature()) {
    // Checked before the decomposition, which is the slow part.
    RequireTemperatureFor(temperature_c, y.size());
    internal::RequireChannelsFor(options, temperature_c.cols());
    for (Eigen::Index c = 0; c < temperature_c.cols(); ++c) {
      RequireVaryingSignal("temperature", temperature_c.col(c),
                           "a drift model on temperature needs a record whose temperature changes");
    }
  }
  DriftOptions o = options;
  o.features = ForTrainingRecord(o.features, y.size());
  internal::SubSeries prepared = internal::PrepareSubSeries(y, o, /*report=*/true);
  const Eigen::MatrixXd thermal = ThermalOrEmpty(prepared.model, temperature_c, y.size());
  const bool decomposed = UsesDecomposition(options.method);
  if (options.progress)
    options.progress(decomposed ? internal::kGroupsDoneShare : 0.0, "fit sub-models");
  internal::FitLearners(prepared.model, prepared.series, y, thermal, y.size(), temperature_c,
                        record_starts);
  if (prepared.model.uses_temperature()) {
    prepared.model.temperature_min_c = temperature_c.col(0).minCoeff();
    prepared.model.temperature_max_c = temperature_c.col(0).maxCoeff();
  }
  if (options.progress) options.progress(1.0, "fit sub-models");
  return std::move(prepared.model);
}

double ShareOutsideRange(const Eigen::Ref<const Eigen::VectorXd>& temperature_c, double min_c,
                         double max_c) {
  if (!(min_c <= max_c) || temperature_c.size() == 0) return 0.0;
  const auto outside = (temperature_c.array() < min_c) || (temperature_c.array() > max_c);
  return static_cast<double>(outside.count()) / static_cast<double>(temperature_c.size());
}

Eigen::MatrixXd EstimateDriftWithSd(const DriftModel& model,
                                    const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                                    const std::vector<Eigen::Index>& record_starts) {
  if (model.options.mode != Mode::kCompensate) {
    throw UsageError(
        "model mode = predict: drift estimation needs a model fitted with --mode compensate");
  }
  if (!record_starts.empty()) {
    // Every record on its own: each starts in equilibrium at its first temperature.
    CheckRecordStarts(record_starts, temperature_c.rows());
    Eigen::MatrixXd out(temperature_c.rows(), 2);
    ForEachRecord(temperature_c.rows(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      out.middleRows(begin, length) =
          EstimateDriftWithSd(model, temperature_c.middleRows(begin, length));
    });
    return out;
  }
  const Eigen::Index n = temperature_c.rows();
  if (temperature_c.cols() != model.temperature_channels()) {
    throw DataError("the model takes " + std::to_string(model.temperature_channels()) +
                    " temperature channel(s), " + std::to_string(temperature_c.cols()) +
                    " given");
  }
  // Equilibrium at the reference: a one-sample record starts (and stays) in equilibrium.
  const bool referenced = !std::isnan(model.options.reference_c);
  const Eigen::MatrixXd t_ref =
      Eigen::MatrixXd::Constant(1, temperature_c.cols(), model.options.reference_c);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, 2);
  bool every_band = true;
  Eigen::MatrixXd f;
  Eigen::MatrixXd f_ref;
  for (const auto& sub : model.sub_models) {
    if (sub.thermal) {
      const Eigen::MatrixXd e = sub.thermal->EstimateWithSd(temperature_c);
      out.col(0) += e.col(0);
      out.col(1) += e.col(1).cwiseAbs2();
      if (referenced) out.col(0).array() -= sub.thermal->Estimate(t_ref)[0];
      continue;
    }
    every_band = false;
    if (!sub.learner) continue;
    if (f.size() == 0) {
      const FeatureOptions features = EffectiveFeatures(model.options);
      f = ThermalFeatures(temperature_c.col(0), features);
      if (referenced) f_ref = ThermalFeatures(t_ref.col(0), features);
    }
    out.col(0) += sub.learner->Predict(f);
    if (referenced) out.col(0).array() -= sub.learner->Predict(f_ref)[0];
  }
  if (every_band) {
    out.col(1) = out.col(1).cwiseSqrt();
  } else {
    out.col(1).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

Eigen::VectorXd EstimateDrift(const DriftModel& model,
                              const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                              const std::vector<Eigen::Index>& record_starts) {
  return EstimateDriftWithSd(model, temperature_c, record_starts).col(0);
}

namespace {

// The decomposition a fitted model applies to new data: its options with its seed, and no noise
// EMDs a caller may have left in them (they serve one record length; the causal windows build
// their own).
decomposition::DecompositionOptions DecompositionFor(const DriftModel& model) {
  decomposition::DecompositionOptions dopt = model.options.decomposition;
  dopt.seed = model.options.seed;
  dopt.noise_emds = nullptr;
  return dopt;
}

// Causal protocol: the lags of each origin o = origin + r come from decomposing the trailing
// window y[o-W .. o-1] alone (lags[g](r, k) = s_g[o - 1 - k] of that window's groups); windows
// run in parallel.
std::vector<Eigen::MatrixXd> CausalLags(const DriftModel& model,
                                        const Eigen::Ref<const Eigen::VectorXd>& y,
                                        Eigen::Index origin, Eigen::Index count,
                                        const CausalOptions& causal) {
  decomposition::DecompositionOptions dopt = DecompositionFor(model);
  dopt.threads = 1;
  if (causal.ensemble_size > 0) dopt.ensemble_size = causal.ensemble_size;
  // Every full window has one length, seed and ensemble, hence the same white-noise EMDs:
  // computed once here instead of once per window (the same bits; about half of each window's
  // cost), when they take at most 256 MB (about ensemble x log2(W) windows' worth of samples).
  decomposition::DecompositionOptions dopt_full = dopt;
  const Eigen::Index last_origin = origin + count - 1;
  const Eigen::Index full_windows = last_origin - std::max<Eigen::Index>(origin, causal.window) + 1;
  const double cache_bytes = static_cast<double>(dopt.ensemble_size) *
                             decomposition::NoiseEmds::RowsPerRealisation(causal.window) *
                             static_cast<double>(causal.window) * sizeof(double);
  // Shared, the noise EMDs are computed to the end; a window computes only the rows it uses
  // (few, when BEEMDAN's bound stops early): sharing pays from a few windows on.
  if (decomposition::UsesNoiseEmds(dopt.method) && full_windows >= 16 && cache_bytes <= 256e6) {
    decomposition::DecompositionOptions build = dopt;
    build.threads = causal.threads;
    dopt_full.noise_emds = std::make_shared<const decomposition::NoiseEmds>(causal.window, build);
  }
  const int p = model.lags;
  const size_t groups = model.sub_models.size();
  std::vector<Eigen::MatrixXd> lags(groups, Eigen::MatrixXd(count, p));
  std::atomic<Eigen::Index> windows_done{0};
  std::mutex progress_mutex;
  double reported = 0.0;
  const Eigen::Index report_every = std::max<Eigen::Index>(1, count / 200);
  ParallelFor(static_cast<int>(count), causal.threads, [&](int r, int) {
    const Eigen::Index end = origin + r;  // the window ends just before the origin
    const Eigen::Index start = std::max<Eigen::Index>(0, end - causal.window);
    const Eigen::Index length = end - start;
    const Eigen::MatrixXd series =
        GroupSeries(model, decomposition::Decompose(y.segment(start, length),
                                                    length == causal.window ? dopt_full : dopt));
    for (size_t g = 0; g < groups; ++g) {
      for (int k = 0; k < p; ++k) {
        lags[g](r, k) = series(length - 1 - k, static_cast<Eigen::Index>(g));
      }
    }
    const Eigen::Index done = ++windows_done;
    if (causal.progress && (done % report_every == 0 || done == count)) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      const double fraction = static_cast<double>(done) / static_cast<double>(count);
      if (fraction > reported) {
        reported = fraction;
        causal.progress(fraction);
      }
    }
  });
  return lags;
}

// Recursive prediction from each row's lags at its origin (lags[g](r, k) = s_g[origin + r - 1 -
// k]): step j predicts s_g[origin + r + j] from the lags (the predictions of the steps before
// standing in for the samples after the origin) and the thermal inputs at origin + r + j - 1, read
// from the record. The last step, summed over the groups, is the prediction of y[origin + r +
// horizon - 1].
Eigen::VectorXd PredictRecursively(const DriftModel& model,
                                   const std::vector<Eigen::MatrixXd>& lags,
                                   const Eigen::Ref<const Eigen::MatrixXd>& thermal,
                                   Eigen::Index origin, int horizon) {
  const int p = model.lags;
  const Eigen::Index count = lags.front().rows();
  Eigen::VectorXd prediction = Eigen::VectorXd::Zero(count);
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    Eigen::MatrixXd x(count, p + thermal.cols());
    x.leftCols(p) = lags[g];
    for (int j = 0; j < horizon; ++j) {
      if (thermal.cols() > 0) {
        x.rightCols(thermal.cols()) = thermal.middleRows(origin + j - 1, count);
      }
      Eigen::VectorXd step = model.sub_models[g].learner->Predict(x);
      if (j + 1 == horizon) {
        prediction += step;
        break;
      }
      for (int k = p - 1; k > 0; --k) x.col(k) = x.col(k - 1);
      x.col(0) = std::move(step);
    }
  }
  return prediction;
}

}  // namespace

Eigen::VectorXd PredictFromSeries(const DriftModel& model,
                                  const Eigen::Ref<const Eigen::MatrixXd>& series,
                                  const Eigen::Ref<const Eigen::MatrixXd>& thermal,
                                  Eigen::Index first, Eigen::Index count, int horizon) {
  const Eigen::Index needed = internal::FirstPredictable(model.lags, false, horizon);
  if (first < needed) {
    throw DataError("prediction of sample " + std::to_string(first + 1) + " " +
                    std::to_string(horizon) + " steps ahead needs " + std::to_string(needed) +
                    " samples before it");
  }
  const Eigen::Index origin = first - (horizon - 1);
  std::vector<Eigen::MatrixXd> lags(model.sub_models.size());
  for (size_t g = 0; g < lags.size(); ++g) {
    lags[g] = LagRows(series.col(static_cast<Eigen::Index>(g)), model.lags, origin, count);
  }
  return PredictRecursively(model, lags, thermal, origin, horizon);
}

Eigen::VectorXd PredictAhead(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                             const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                             Eigen::Index first, int horizon, Protocol protocol,
                             const CausalOptions& causal) {
  if (model.options.mode != Mode::kPredict) {
    throw UsageError(
        "model mode = compensate: prediction needs a model fitted with --mode predict");
  }
  RequireFiniteSignal("target", y, 2);
  const Eigen::Index n = y.size();
  causal.Validate();
  const Eigen::Index min_first = FirstPredictable(model, protocol, horizon);
  if (first < min_first || first >= n) {
    throw DataError(
        "first predicted sample " + std::to_string(first + 1) + " must be in [" +
        std::to_string(min_first + 1) + ", " + std::to_string(n) +
        "] (the model needs that much history" +
        (horizon > 1 ? " before its " + std::to_string(horizon) + "-step horizon" : "") + ")");
  }
  const Eigen::MatrixXd thermal = ThermalOrEmpty(model, temperature_c, n);
  const Eigen::Index count = n - first;
  const Eigen::Index origin = first - (horizon - 1);  // origin of the prediction of y[first]
  if (!UsesDecomposition(model.options.method)) {
    return PredictFromSeries(model, y, thermal, first, count, horizon);
  }
  if (protocol == Protocol::kPaper) {
    decomposition::DecompositionOptions dopt = DecompositionFor(model);
    dopt.threads = model.options.threads;
    const Eigen::MatrixXd series = GroupSeries(model, decomposition::Decompose(y, dopt));
    return PredictFromSeries(model, series, thermal, first, count, horizon);
  }
  return PredictRecursively(model, CausalLags(model, y, origin, count, causal), thermal, origin,
                            horizon);
}

void CausalOptions::Validate() const {
  if (window < 16 || window > 1000000) {
    ThrowOption("causal window", std::to_string(window), "an integer in [16, 1000000]");
  }
  if (ensemble_size < 0 || ensemble_size > 100000) {
    ThrowOption("causal ensemble_size", std::to_string(ensemble_size),
                "an integer in [0, 100000] (0 = the model's)");
  }
}

Eigen::Index FirstPredictable(const DriftModel& model, Protocol protocol, int horizon) {
  return internal::FirstPredictable(
      model.lags, protocol == Protocol::kCausal && UsesDecomposition(model.options.method),
      horizon);
}

std::string CausalWindowNote(const DriftModel& model, int window) {
  if (!UsesDecomposition(model.options.method) || window < 2) return "";
  const int resolved = std::max(1, static_cast<int>(std::floor(std::log2(window))) - 1);
  std::vector<std::string> names;
  int slowest = 0;
  for (const SubModel& sub : model.sub_models) {
    // The noise group's energy sits in its first IMFs (white noise loses about half per mode):
    // the slow ones it loses to the residue barely change its series.
    if (sub.has_residue || sub.imfs.empty() || sub.name == "noise") continue;
    const int last = *std::max_element(sub.imfs.begin(), sub.imfs.end());
    if (last <= resolved) continue;
    const int first = *std::min_element(sub.imfs.begin(), sub.imfs.end());
    names.push_back("'" + sub.name + "'" +
                    (first == last
                         ? ""
                         : " (IMFs " + std::to_string(first) + "-" + std::to_string(last) + ")"));
    slowest = std::max(slowest, last);
  }
  if (names.empty()) return "";
  std::string list = names.front();
  if (names.size() == 2) list += " and " + names.back();
  if (names.size() > 2) list += " ... " + names.back() + " (" + std::to_string(names.size()) + ")";
  const bool several = names.size() > 1;
  const long long needed = 1LL << std::min(slowest + 1, 40);
  return "note: a " + std::to_string(window) + "-sample causal window resolves about " +
         std::to_string(resolved) + " IMFs; sub-model" + (several ? "s " : " ") + list +
         (several ? " hold" : " holds") + " slower ones, which fall into the window's residue: " +
         (several ? "they see" : "it sees") + " another series than in training (" +
         (needed <= 1000000
              ? "a window of " + std::to_string(needed) + " samples would resolve them"
              : "no window up to 1000000 samples resolves them") +
         ")";
}

Eigen::VectorXd PredictOneStep(const DriftModel& model, const Eigen::Ref<const Eigen::VectorXd>& y,
                               const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                               Eigen::Index first, Protocol protocol, const CausalOptions& causal) {
  return PredictAhead(model, y, temperature_c, first, 1, protocol, causal);
}

}  // namespace gyrodrift::drift
