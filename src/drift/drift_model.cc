// The drift model's definition: the Mode / Method / Protocol names, DriftOptions (defaults and
// Validate), the DriftModel accessors and Summary, and the facts every step reads off a method
// (UsesDecomposition, IdentifiesThermalModel, EffectiveFeatures, GroupSeries). The fit is in
// drift_fit.cc (MS-ELM's and EMD-ELM's own steps in ms_elm.cc and emd_elm.cc), compensate-mode estimation in compensation.cc, prediction in prediction.cc and
// the causal protocol in causal_protocol.cc.
#include "gyrodrift/drift/drift_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "common/enum_names.h"
#include "drift/fit_steps.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {
namespace {

constexpr std::array<std::pair<Mode, std::string_view>, 2> kModes{{
    {Mode::kPredict, "predict"},
    {Mode::kCompensate, "compensate"},
}};
constexpr std::array<std::pair<Method, std::string_view>, 14> kMethods{{
    {Method::kMsElm, "ms-elm"},
    {Method::kElm, "elm"},
    {Method::kEmdElm, "emd-elm"},
    {Method::kPoly, "poly"},
    {Method::kSvr, "svr"},
    {Method::kBp, "bp"},
    {Method::kThermal, "thermal"},
    {Method::kPersistence, "persistence"},
    {Method::kTrailingMean, "trailing-mean"},
    {Method::kExpSmoothing, "exp-smoothing"},
    {Method::kKalmanLevel, "kalman-level"},
    {Method::kKalmanTrend, "kalman-trend"},
    {Method::kNone, "none"},
    {Method::kConstant, "constant"},
}};
constexpr std::array<std::pair<Protocol, std::string_view>, 2> kProtocols{{
    {Protocol::kPaper, "paper"},
    {Protocol::kCausal, "causal"},
}};

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;

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
  if (method == Method::kThermal) return mode == Mode::kCompensate;
  // The filters forecast the measured output, which a compensation never has at run time.
  if (IsBaseline(method) && method != Method::kNone && method != Method::kConstant) {
    return mode == Mode::kPredict;
  }
  return true;
}

std::vector<Method> ReferenceMethods() { return {Method::kNone, Method::kConstant}; }

std::vector<Method> AllMethods(Mode mode) {
  std::vector<Method> all;
  for (const auto& [m, name] : kMethods) {
    if (SupportsMode(m, mode) && m != Method::kNone && m != Method::kConstant) all.push_back(m);
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
  ValidateNested("decomposition", [&] { decomposition.Validate(); });
  ValidateNested("selection", [&] { selection.Validate(); });
  ValidateNested("features", [&] { EffectiveFeatures(*this).Validate(); });
  if (reference_c) RequireInRange("reference_c", *reference_c, -100.0, 200.0);
  if (!SupportsMode(method, mode)) {
    ThrowOption("method", std::string(ToString(method)),
                "a method of " + std::string(ToString(mode)) + " mode (" +
                    (method == Method::kThermal
                         ? "thermal identifies a compensation model: mode = compensate"
                         : "a filter of the measured output forecasts it: mode = predict") +
                    ")");
  }
  ValidateNested("thermal", [&] { thermal.Validate(); });
  LearnerOptions l = learner;
  l.kind = internal::KindOf(method);
  ValidateNested("learner", [&] { l.Validate(); });
  for (int p : lag_candidates) {
    if (p < 1 || p > 256) ThrowOption("lag_candidates", std::to_string(p), "an integer in [1, 256]");
  }
  if (auto_lags && lag_candidates.empty()) {
    ThrowOption("lag_candidates", "(empty)", "at least one candidate when lags are 'auto'");
  }
  RequireInRange("validation_fraction", validation_fraction, 0.05, 0.5);
}

bool DriftOptions::uses_temperature() const {
  return mode == Mode::kCompensate || (features.use_temperature && !IsBaseline(method));
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
  if (sub_models.size() == 1 && sub_models.front().baseline) {
    return std::string(ToString(options.method)) + " (" + std::string(ToString(options.mode)) +
           "): " + sub_models.front().baseline->Summary() + ", trained on " +
           std::to_string(training_samples) + " samples";
  }
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

}  // namespace gyrodrift::drift
