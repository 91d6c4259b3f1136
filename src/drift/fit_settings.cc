#include "gyrodrift/drift/fit_settings.h"

#include <charconv>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {
namespace {

// "auto" or an integer in [lo, hi], the value of setting `name`; -1 for "auto".
int AutoOrInteger(std::string_view name, const std::string& text, int lo, int hi) {
  if (text == "auto") return -1;
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < lo || value > hi) {
    ThrowOption(name, "'" + text + "'",
                "auto or an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

// The enum named `text`, a refusal naming the setting rather than the field it sets.
template <class Parse>
auto Named(std::string_view name, const std::string& text, Parse parse) {
  try {
    return parse(text);
  } catch (const OptionError& e) {
    throw OptionError(std::string(name), e.value(), e.rule());
  }
}

bool ElmBased(Method method) {
  return method == Method::kMsElm || method == Method::kEmdElm || method == Method::kElm;
}

// The settings of the compensation's reference and of the thermal identification (compensate
// mode, identified methods), onto `o` (its mode and method set).
void ThermalSettings(const FitSettings& s, DriftOptions& o) {
  if (s.reference_temperature) {
    const std::string value = FormatValue(*s.reference_temperature);
    if (o.mode != Mode::kCompensate) {
      ThrowOption("reference_temperature", value, "unset in mode 'predict'");
    }
    RequireInRange("reference_temperature", *s.reference_temperature, -100.0, 200.0);
    o.reference_c = *s.reference_temperature;
  }
  o.thermal.hysteresis = Named("hysteresis", s.hysteresis, HysteresisTermFromString);
  if (o.thermal.hysteresis != HysteresisTerm::kAuto && !IdentifiesThermalModel(o)) {
    ThrowOption("hysteresis", "'" + s.hysteresis + "'",
                "auto unless mode is 'compensate' with method thermal, ms-elm or emd-elm");
  }
  o.thermal.standard_errors = s.standard_errors;
  if (s.standard_errors != ThermalModelOptions{}.standard_errors && !IdentifiesThermalModel(o)) {
    ThrowOption("standard_errors", FormatValue(s.standard_errors),
                "left at its default unless mode is 'compensate' with method thermal, ms-elm or "
                "emd-elm");
  }
}

}  // namespace

Execution MakeExecution(const FitSettings& s) {
  const Execution execution{.threads = s.threads};
  execution.Validate();
  return execution;
}

void FitSettings::Validate() const {
  (void)MakeDriftOptions(*this);  // which checks the threads too
}

Method ResolveMethod(std::string_view method, Mode mode) {
  if (method == "auto") return mode == Mode::kCompensate ? Method::kThermal : Method::kMsElm;
  // The names this mode takes (a method of the other mode is refused where the mode is known,
  // with its reason).
  std::string allowed = "auto";
  std::vector<Method> methods = AllMethods(mode);
  for (Method m : ReferenceMethods()) {
    if (SupportsMode(m, mode)) methods.push_back(m);
  }
  for (Method m : methods) {
    if (ToString(m) == method) return m;
    allowed += ", " + std::string(ToString(m));
  }
  for (Method m : AllMethods(mode == Mode::kCompensate ? Mode::kPredict : Mode::kCompensate)) {
    if (ToString(m) == method) return m;
  }
  ThrowOption("method", "'" + std::string(method) + "'",
              "one of " + allowed + " (in " + std::string(ToString(mode)) + " mode)");
}

DriftOptions MakeDriftOptions(const FitSettings& s) {
  DriftOptions o;
  o.mode = Named("mode", s.mode, ModeFromString);
  o.method = Named("method", s.method, [&](const std::string& m) { return ResolveMethod(m, o.mode); });
  const std::string method(ToString(o.method));
  o.decomposition.method = Named("decomposition", s.decomposition, decomposition::MethodFromString);
  o.decomposition.ensemble_size = s.ensemble;
  o.selection.monte_carlo.realisations = s.realisations;
  o.seed = s.seed;
  MakeExecution(s);  // the threads are the fit's execution, checked here with the rest
  o.features.rate_hz = s.rate_hz;
  o.features.thermal_set = Named("thermal_features", s.thermal_features, ThermalSetFromString);
  if (!s.time_constants.empty()) {
    o.features.time_constants_s = s.time_constants;
    o.features.limit_time_constants = false;  // the user's constants, all of them
  }
  const bool compensate = o.mode == Mode::kCompensate;
  if (compensate && !s.has_temperature) {
    throw UsageError(
        "mode 'compensate' needs a temperature channel (the compensation model runs on "
        "temperature alone)");
  }
  o.features.use_temperature = !compensate && s.has_temperature;

  if (!s.lags.empty()) {
    const int p = AutoOrInteger("lags", s.lags, 1, 256);
    if (compensate) {
      ThrowOption("lags", s.lags,
                  "left unset in mode 'compensate' (a compensate-mode model sees temperature "
                  "only; lags apply to mode 'predict')");
    }
    o.auto_lags = p < 0;
    if (p > 0) o.features.lags = p;
  }
  if (s.nonlinear) {
    if (!IdentifiesThermalModel(o)) {
      ThrowOption("nonlinear", "true",
                  "false unless mode is 'compensate' with method thermal, ms-elm or emd-elm");
    }
    o.linear_compensation = false;
  }
  if (!s.hidden.empty()) {
    const int hidden = AutoOrInteger("hidden", s.hidden, 1, elm::kMaxHiddenUnits);
    if (hidden > 0) {
      if (!ElmBased(o.method)) {
        ThrowOption("hidden", s.hidden,
                    "auto for method '" + method +
                        "' (it applies to the ELM methods: ms-elm, emd-elm, elm)");
      }
      // An identified model reads no ELM setting: its sub-models are linear and its nonlinear
      // correction chooses its own hidden units.
      if (compensate && o.method != Method::kElm) {
        ThrowOption("hidden", s.hidden,
                    "auto for compensate-mode " + method +
                        ", which fits linear sub-models and chooses its nonlinear correction's "
                        "units itself (docs/drift.md 1.2; it applies to mode 'predict' and "
                        "method 'elm')");
      }
      o.learner.elm.selection = elm::Selection::kFixed;
      o.learner.elm.hidden_units = hidden;
    }
  }
  ThermalSettings(s, o);
  // The fields of DriftOptions a setting sets: a refusal of one names the setting.
  ValidateAsSettings({{"decomposition.ensemble_size", "ensemble"},
                      {"selection.monte_carlo.realisations", "realisations"},
                      {"features.lags", "lags"},
                      {"features.time_constants_s", "time_constants"},
                      {"features.rate_hz", "rate_hz"},
                      {"learner.elm.hidden_units", "hidden"},
                      {"thermal.standard_errors", "standard_errors"}},
                     [&] { o.Validate(); });
  return o;
}

}  // namespace gyrodrift::drift
