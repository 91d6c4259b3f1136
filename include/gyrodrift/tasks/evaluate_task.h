// The `evaluate` user operation, written once for every front end (issue 25): the methods
// compared on a chronological split of one record (drift::Evaluate), their settings by name, the
// method-list and protocol rules, and the records the table CSV and its sidecar hold.
// `gyrodrift evaluate` and the Python package's `evaluate` call these and nothing below them.
//
// Cost: drift::Evaluate's (a fit and a test run per method, protocol and repeat).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/drift/fit_settings.h"

namespace gyrodrift::tasks {

namespace internal {
inline const drift::EvaluationOptions kEvaluationDefaults{};
}  // namespace internal

struct EvaluateSettings {
  // The models' settings, as fit's (the method is the list's: "ms-elm" stands in; a hidden-unit
  // count in compensate mode is elm's and checked as such).
  drift::FitSettings fit;
  // "all" (every method of the mode) or a comma-separated list without repeats.
  std::string methods = "all";
  std::string protocol = "both";  // paper | causal | both
  double split = internal::kEvaluationDefaults.split;
  int repeats = internal::kEvaluationDefaults.repeats;
  drift::CausalOptions causal = internal::kEvaluationDefaults.causal;  // the causal windows
  int horizon = internal::kEvaluationDefaults.horizon;

  // The evaluation's options, validated; `methods_name` names the method list in messages
  // ("methods", or the flag "--methods"). OptionError naming the field (split, repeats, protocol,
  // causal.window, causal.mirror, causal.windows, causal.ensemble_size, horizon, methods) or
  // UsageError.
  drift::EvaluationOptions Options(std::string_view methods_name = "methods") const;
  void Validate(std::string_view methods_name = "methods") const;  // Options() and fit's
};

// --methods: "all" (every drift::Method of `mode`) or a comma-separated list of method names
// (spaces around a name ignored), without repeats or empty items. Throws UsageError / OptionError
// naming `name`.
std::vector<drift::Method> ParseMethods(const std::string& text, drift::Mode mode,
                                        std::string_view name = "methods");

struct EvaluateRun {
  drift::DriftOptions base;          // the models' options
  drift::EvaluationOptions options;  // the evaluation's
  int threads = 0;
  drift::EvaluationResult result;
};

// Scores every method on y (its truth when given, else y itself), at settings.fit.rate_hz.
EvaluateRun RunEvaluate(const Eigen::VectorXd& y, const Eigen::MatrixXd& temperature,
                        const Eigen::VectorXd& truth, const EvaluateSettings& settings,
                        std::function<void(double, std::string_view)> progress = {},
                        std::string_view methods_name = "methods");

// The table CSV (method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,train_s,
// predict_s).
std::string EvaluateTableCsv(const drift::EvaluationResult& result);

// What the record was read from, for the sidecar.
struct EvaluateInput {
  std::string input = {}, target_column = {}, temperature_column = {}, truth_column = {},
      rate_hz_from = {};
  Eigen::Index samples = 0;
};

// The sidecar (but for its header): options (the drift options in full) and result.
nlohmann::json EvaluateRecord(const EvaluateRun& run, const EvaluateInput& in);

// The notes of the rows ("<method>, <note>"), the note that predictions several steps ahead read
// the temperature up to the predicted sample, and, when test temperatures lie beyond the training
// block's, the note that thermal models extrapolate; one line each.
std::string EvaluateNotes(const EvaluateRun& run);

}  // namespace gyrodrift::tasks
