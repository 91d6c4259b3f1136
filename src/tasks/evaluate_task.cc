#include "gyrodrift/tasks/evaluate_task.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/baseline.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::tasks {
namespace {

using nlohmann::json;

std::vector<drift::Protocol> ParseProtocols(const std::string& text) {
  if (text == "both") return {drift::Protocol::kPaper, drift::Protocol::kCausal};
  if (text != "paper" && text != "causal")
    ThrowOption("protocol", "'" + text + "'", "paper, causal or both");
  return {drift::ProtocolFromString(text)};
}

json RowRecord(const drift::EvaluationRow& r) {
  return {{"method", drift::ToString(r.method)},
          {"protocol", drift::ToString(r.protocol)},
          {"rmse", r.rmse},
          {"rmse_std", r.rmse_std},
          {"mae", r.mae},
          {"max_abs", r.max_abs},
          {"rmse_measured", r.rmse_measured},
          // null: a test block shorter than one 10-min block
          {"slow_removed", std::isfinite(r.slow_removed) ? json(r.slow_removed) : json(nullptr)},
          {"train_s", r.train_s},
          {"predict_s", r.predict_s},
          {"model_summary", r.model_summary},
          {"notes", r.notes}};
}

// The models' settings: fit's, with "ms-elm" standing in for the method (the list is the
// evaluation's).
drift::FitSettings ModelSettings(const EvaluateSettings& s) {
  drift::FitSettings fit = s.fit;
  fit.method = "ms-elm";
  return fit;
}

// The options every evaluated method starts from (each row sets its own method). A hidden-unit
// count in compensate mode is elm's (an identified ms-elm reads none and refuses one), so it is
// checked as elm's, with the settings only the identified methods take left at their defaults,
// and applied to the ms-elm base.
drift::DriftOptions BaseOptions(const EvaluateSettings& s) {
  drift::FitSettings fit = ModelSettings(s);
  const bool count = !fit.hidden.empty() && fit.hidden != "auto";
  if (fit.mode != "compensate" || !count) return drift::MakeDriftOptions(fit);
  drift::FitSettings elm = fit;
  elm.method = "elm";
  elm.nonlinear = drift::FitSettings{}.nonlinear;
  elm.hysteresis = drift::FitSettings{}.hysteresis;
  elm.standard_errors = drift::FitSettings{}.standard_errors;
  const drift::DriftOptions counted = drift::MakeDriftOptions(elm);
  fit.hidden = "auto";
  drift::DriftOptions base = drift::MakeDriftOptions(fit);
  base.learner.elm = counted.learner.elm;
  return base;
}

}  // namespace

// "all" or a comma-separated list; an empty item (a trailing comma) or a repeat is an error: a
// repeated method would give two model files of one name in the demo.
std::vector<drift::Method> ParseMethods(const std::string& text, drift::Mode mode,
                                        std::string_view name) {
  if (text == "all") return drift::AllMethods(mode);
  std::vector<drift::Method> methods;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    drift::Method m;
    try {
      m = drift::MethodFromString(item);
    } catch (const UsageError&) {
      // The names this mode takes, as fit's refusal lists them (a method of the other mode is
      // refused below with its reason).
      std::string allowed;
      std::vector<drift::Method> names = drift::AllMethods(mode);
      for (drift::Method r : drift::ReferenceMethods()) names.push_back(r);
      for (drift::Method n : names) allowed += ", " + std::string(drift::ToString(n));
      ThrowOption(name, "'" + text + "'",
                  fmt::format("all or a comma-separated list of {} ({} mode; '{}' is none of them)",
                              allowed.substr(2), drift::ToString(mode), item));
    }
    if (std::find(methods.begin(), methods.end(), m) != methods.end()) {
      ThrowOption(name, "'" + text + "'", "a list without repeats");
    }
    // Refused here, before any work, rather than when the method's turn comes.
    if (!drift::SupportsMode(m, mode)) {
      ThrowOption(name, "'" + text + "'",
                  fmt::format("methods of {} mode ({} is not one)", drift::ToString(mode), item));
    }
    methods.push_back(m);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return methods;
}

drift::EvaluationOptions EvaluateSettings::Options(std::string_view methods_name) const {
  const drift::Mode mode = BaseOptions(*this).mode;
  drift::EvaluationOptions e;
  e.split = split;
  e.repeats = repeats;
  e.methods = ParseMethods(methods, mode, methods_name);
  e.protocols = ParseProtocols(protocol);
  e.causal = causal;
  e.horizon = horizon;
  e.Validate();
  return e;
}

void EvaluateSettings::Validate(std::string_view methods_name) const {
  (void)Options(methods_name);  // the models' settings first
}

EvaluateRun RunEvaluate(const Eigen::VectorXd& y, const Eigen::MatrixXd& temperature,
                        const Eigen::VectorXd& truth, const EvaluateSettings& settings,
                        std::function<void(double, std::string_view)> progress,
                        std::string_view methods_name) {
  EvaluateRun run;
  run.base = BaseOptions(settings);
  Execution execution = drift::MakeExecution(ModelSettings(settings));
  run.options = settings.Options(methods_name);
  run.threads = execution.threads;
  execution.progress = std::move(progress);
  run.result = drift::Evaluate(y, temperature, truth, run.base, run.options, execution);
  return run;
}

std::string EvaluateTableCsv(const drift::EvaluationResult& result) {
  std::string csv =
      "method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,train_s,predict_s\n";
  for (const auto& r : result.rows) {
    csv += std::string(drift::ToString(r.method)) + "," + std::string(drift::ToString(r.protocol));
    for (double v : {r.rmse, r.rmse_std, r.mae, r.max_abs, r.rmse_measured, r.slow_removed,
                     r.train_s, r.predict_s}) {
      csv += "," + io::FormatDouble(v);
    }
    csv += "\n";
  }
  return csv;
}

json EvaluateRecord(const EvaluateRun& run, const EvaluateInput& in) {
  json methods = json::array(), protocols = json::array();
  for (auto m : run.options.methods) methods.push_back(drift::ToString(m));
  for (auto p : run.options.protocols) protocols.push_back(drift::ToString(p));
  const drift::EvaluationResult& result = run.result;
  json j;
  j["options"] = {{"input", in.input},
                  {"target_column", in.target_column},
                  {"temperature_column", in.temperature_column},
                  {"truth_column", in.truth_column},
                  {"split", run.options.split},
                  {"repeats", run.options.repeats},
                  {"methods", methods},
                  {"protocols", protocols},
                  {"window", run.options.causal.window},
                  {"mirror", run.options.causal.mirror},
                  {"windows", run.options.causal.windows},
                  {"causal_ensemble", run.options.causal.ensemble_size},
                  {"horizon", run.options.horizon},
                  {"rate_hz_from", in.rate_hz_from},
                  {"threads", run.threads},
                  {"drift", io::DriftOptionsToJson(run.base)}};
  json rows = json::array();
  for (const auto& r : result.rows) rows.push_back(RowRecord(r));
  j["result"] = {{"mode", drift::ToString(result.mode)},
                 {"test_outside_training_temperature_share",
                  result.test_outside_training_temperature_share},
                 {"samples", in.samples},
                 {"first_test_sample", result.split_index + 1},
                 {"test_samples", in.samples - result.split_index},
                 {"scored_against", result.against_truth ? in.truth_column : in.target_column},
                 {"slow_variation_block_s", drift::kSlowVariationBlockS},
                 {"rows", rows}};
  return j;
}

std::string EvaluateNotes(const EvaluateRun& run) {
  const drift::EvaluationResult& result = run.result;
  std::string notes;
  for (const auto& r : result.rows) {
    for (const std::string& note : r.notes) {
      notes += std::string(drift::ToString(r.method)) + ", " + note + "\n";
    }
  }
  // The recursion of an H-step prediction reads the temperature of each step it predicts: a
  // temperature known ahead (a chamber's programme), which the baselines do not read.
  const bool reads_temperature = run.base.uses_temperature() &&
                                 std::any_of(run.options.methods.begin(), run.options.methods.end(),
                                             [](drift::Method m) { return !drift::IsBaseline(m); });
  if (result.mode == drift::Mode::kPredict && run.options.horizon > 1 && reads_temperature) {
    notes += fmt::format(
        "note: the {}-step predictions of the methods given a temperature read it up to the "
        "predicted sample (a temperature programme known ahead); the baselines read none\n",
        run.options.horizon);
  }
  // Test temperatures beyond the training block's make every thermal model extrapolate.
  const double outside = result.test_outside_training_temperature_share;
  if (outside > 0.0) {
    notes += fmt::format(
        "note: {:.1f} % of the test samples lie outside the training temperature range "
        "[{:.4g}, {:.4g}] degC: thermal models extrapolate there\n",
        100.0 * outside, result.training_temperature_min_c, result.training_temperature_max_c);
  }
  return notes;
}

}  // namespace gyrodrift::tasks
