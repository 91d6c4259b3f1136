// The drift-model settings a user gives by name, and their one mapping onto DriftOptions.
//
// `gyrodrift fit` and `gyrodrift evaluate` (flags), the Python package's DriftModel.fit and
// evaluate (keywords) and a fleet calibration manifest (keys) all go through MakeDriftOptions, so
// the front ends accept the same values, mean the same thing by them and refuse the same mistakes
// with the same message. A refusal names the setting as FitSettings does (`lags`,
// `reference_temperature`): the Python keyword; the CLI names the flag bound to it
// (apps/gyrodrift/cli_util.h, BindSetting).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

struct FitSettings {
  std::string mode;                       // "predict" | "compensate" (required)
  // "auto" (ms-elm in predict mode, the paper's model; thermal in compensate mode, which beat the
  // per-group identification of ms-elm: docs/drift.md 4.5) or a Method name.
  std::string method = "auto";
  std::string decomposition = "beemdan";  // a decomposition::Method name (ms-elm, emd-elm)
  // Predict mode: the sub-models' own lags, "auto" (chosen among 1, 2, 4, 8, 16 on the last 20 %
  // of the training record) or p in [1, 256]; "" = not given (4).
  std::string lags = {};
  // The ELM methods: hidden units, "auto" (leave-one-out choice of L <= 50 and C) or L in
  // [1, 100000]; "" = not given (auto).
  std::string hidden = "auto";
  double rate_hz = 1.0;                 // sample rate, Hz
  std::string thermal_features = "auto";  // a ThermalSet name (learners on thermal features)
  std::vector<double> time_constants = {};  // of those features, s; empty: the library's
  int ensemble = 100;                   // decomposition ensemble size
  int realisations = 100;               // white-noise realisations of the grouping's level
  std::uint64_t seed = 1;
  // Worker threads of the fit, in [0, 1024], 0 = every core: how it runs, not a setting of the
  // model (MakeExecution, not MakeDriftOptions, maps it; both check it).
  int threads = 0;
  // Compensate mode, identified methods: each thermal model may add a nonlinear correction.
  bool nonlinear = false;
  // Compensate mode: reference the estimate to equilibrium at this temperature, degC, in
  // [-100, 200]; unset keeps the fitted intercept (the unit's repeatable bias).
  std::optional<double> reference_temperature = {};
  // Compensate mode, identified methods: the thermal models' hysteresis term, a HysteresisTerm
  // name ("auto": for calibration runs of at least kHysteresisAutoMinDurationS).
  std::string hysteresis = "auto";
  // Compensate mode, identified methods: the one-standard-error rule's multiple, in [0, 10]: a
  // richer thermal structure must beat a simpler one by this many standard errors of the paired
  // fold scores to be chosen (0: the least held-out error; docs/drift.md 4.8).
  double standard_errors = ThermalModelOptions{}.standard_errors;
  bool has_temperature = false;  // a temperature channel is given (needed by compensate mode)

  // Every check of MakeDriftOptions and MakeExecution, before any data is read: OptionError
  // naming the setting, or UsageError.
  void Validate() const;
};

// The method "auto" stands for in `mode`.
Method ResolveMethod(std::string_view method, Mode mode);

// DriftOptions of these settings, validated. Throws OptionError naming the setting (value out of
// range, or a setting that does not apply to the mode or method) or UsageError.
DriftOptions MakeDriftOptions(const FitSettings& settings);

// The Execution of the settings' threads (no progress: the front end adds its own), checked:
// OptionError naming `threads`.
Execution MakeExecution(const FitSettings& settings);

}  // namespace gyrodrift::drift
