#include "drift_cli.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "cli_util.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::cli {
namespace {

// The log(s) and their columns.
void AddInputOptions(CLI::App* cmd, DriftArgs* a, bool split_records) {
  if (split_records) {
    cmd->add_option("input", a->inputs,
                    "CSV file(s) with a header row; several calibration logs (same columns and "
                    "sample rate) are fitted as one run, the thermal model's lag states "
                    "restarting at the start of each")
        ->required()
        ->check(kInputFile);
  } else {
    cmd->add_option("input", a->inputs, "CSV file with a header row")
        ->required()
        ->expected(1)
        ->check(kInputFile);
  }
  cmd->add_option("--target,-t", a->target,
                  "column of the gyro output (name or 1-based index); fit takes several, "
                  "comma-separated: one model per axis in one file")
      ->required();
  cmd->add_option("--temperature,-T", a->temperature,
                  "temperature column(s), degC, comma-separated (needed by --mode compensate, "
                  "where the thermal, ms-elm and emd-elm methods take several; in predict mode "
                  "one column adds the thermal history to the lags)");
}

// The compensate-mode settings of the identified thermal models.
void AddThermalOptions(CLI::App* cmd, DriftArgs* a) {
  a->reference_option = BindSetting(
      cmd->add_option(
          "--reference-temperature", a->reference_c,
          "compensate mode: reference the estimate to thermal equilibrium at this temperature, "
          "degC (for a bias calibrated separately); default: keep the fitted intercept, the "
          "unit's repeatable bias"),
      {"reference_temperature"});
  BindSetting(cmd->add_flag("--nonlinear", a->settings.nonlinear,
                            "compensate mode, identified methods: each thermal model may add a "
                            "sigmoid ELM of its regressors, kept only where the blocked "
                            "cross-validation says it helps"),
              {"nonlinear"});
  BindSetting(cmd->add_option("--hysteresis", a->settings.hysteresis,
                              "compensate mode, identified methods: the thermal models' "
                              "hysteresis term (a bias that differs between heating and "
                              "cooling), auto (tried on calibrations with 12 h or more of logged "
                              "samples) | on | off; "
                              "docs/drift.md 4.7")
                  ->capture_default_str(),
              {"hysteresis"});
  BindSetting(cmd->add_option("--standard-errors", a->settings.standard_errors,
                              "compensate mode, identified methods: how many standard errors of "
                              "the held-out fold scores a richer thermal structure must win by to "
                              "be chosen, in [0, 10] (0: the least held-out error); docs/drift.md "
                              "4.8")
                  ->capture_default_str(),
              {"standard_errors"});
}

// The model's other settings and how the fit runs.
void AddModelOptions(CLI::App* cmd, DriftArgs* a) {
  BindSetting(cmd->add_option("--mode", a->settings.mode,
                              "predict (one-step-ahead from past samples) | compensate (drift "
                              "from temperature)")
                  ->required(),
              {"mode"});
  BindSetting(cmd->add_option("--decomposition", a->settings.decomposition,
                              "beemdan|iceemdan|ceemdan|eemd|emd")
                  ->capture_default_str(),
              {"decomposition"});
  BindSetting(cmd->add_option("--lags,-p", a->settings.lags,
                              "own lags per sub-model: auto (chosen on the last 20% of the "
                              "training record among 1,2,4,8,16) or p in [1,256] (predict mode; "
                              "default 4)"),
              {"lags"});
  BindSetting(cmd->add_option("--hidden", a->settings.hidden,
                              "ELM hidden units: auto (leave-one-out choice of L <= 50 and C; "
                              "the default) or a fixed L"),
              {"hidden"});
  a->rate_option = BindSetting(cmd->add_option("--rate-hz", a->settings.rate_hz,
                                               "sample rate, Hz (default: from the steps "
                                               "of a time_s column, else 1)"),
                               {"rate_hz"});
  BindSetting(cmd->add_option("--thermal-features", a->settings.thermal_features,
                              "temperature inputs: auto (classic for poly, ladder otherwise) | "
                              "ladder (rungs between first-order lags of T, the slowest lag, "
                              "(T - 20)^2) | classic (T and its smoothed rate) | lag-bank (T, "
                              "each lag and its rate); docs/drift.md 1.1")
                  ->capture_default_str(),
              {"thermal_features"});
  BindSetting(AddListOption(cmd, "--time-constants", &a->settings.time_constants,
                            "time constants of the thermal lags, seconds, comma-separated "
                            "(default 60,300,900,1800,3600)"),
              {"time_constants"});
  BindSetting(cmd->add_option("--ensemble,-I", a->settings.ensemble, "decomposition ensemble size")
                  ->capture_default_str(),
              {"ensemble"});
  BindSetting(cmd->add_option("--realisations", a->settings.realisations,
                              "white-noise realisations of the ms-elm grouping's Monte-Carlo "
                              "level, >= 20")
                  ->capture_default_str(),
              {"realisations"});
  cmd->add_option("--seed", a->settings.seed, "seed of the decomposition and the learners")
      ->check(kSeed)
      ->capture_default_str();
  BindSetting(cmd->add_option("--threads,-j", a->settings.threads,
                              "worker threads (0 = all cores); results do not depend on it")
                  ->capture_default_str(),
              {"threads"});
}

}  // namespace

void AddDriftOptions(CLI::App* cmd, DriftArgs* a, bool split_records) {
  AddInputOptions(cmd, a, split_records);
  AddThermalOptions(cmd, a);
  AddModelOptions(cmd, a);
  AddLogOptions(cmd, &a->log);
  cmd->add_flag("--quiet,-q", a->quiet, "print nothing on success");
}

void AddCausalWindowOptions(CLI::App* cmd, drift::CausalOptions* causal, const std::string& group) {
  const auto add = [cmd, &group](const std::string& flags, auto& field, const std::string& help,
                                 const char* setting) {
    CLI::Option* option = cmd->add_option(flags, field, help)->capture_default_str();
    if (!group.empty()) option->group(group);
    BindSetting(option, {setting});
  };
  add("--window,-W", causal->window, "causal protocol: longest trailing window W, samples",
      "causal.window");
  add("--mirror", causal->mirror,
      "causal protocol: share of each window mirrored past its end before its decomposition, in "
      "[0, 1]",
      "causal.mirror");
  add("--windows", causal->windows,
      "causal protocol: windows decomposed per origin (test sample), from W down to W/2, their "
      "ends averaged, in [1, 16]",
      "causal.windows");
  add("--causal-ensemble", causal->ensemble_size,
      "causal protocol: realisations of each window's decomposition, in [0, 100000]; 0 = the "
      "model's ensemble",
      "causal.ensemble_size");
}

drift::FitSettings Settings(const DriftArgs& a, const std::string& method) {
  drift::FitSettings s = a.settings;
  s.method = method;
  if (a.reference_option != nullptr && a.reference_option->count() > 0) {
    s.reference_temperature = a.reference_c;
  }
  s.has_temperature = !a.temperature.empty();
  return s;
}

double GivenRateHz(const DriftArgs& a) {
  const bool given = a.rate_option != nullptr && a.rate_option->count() > 0;
  return given ? a.settings.rate_hz : 0.0;
}

}  // namespace gyrodrift::cli
