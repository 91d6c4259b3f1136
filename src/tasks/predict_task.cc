#include "gyrodrift/tasks/predict_task.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::tasks {

void PredictSettings::Validate() const {
  (void)drift::ProtocolFromString(protocol);
  ValidateNested("causal", [&] { causal.Validate(); });
  ValidateThreads(threads);
}

void RequirePredictMode(const io::LoadedModel& loaded, const std::string& model_path) {
  if (loaded.model.options.mode != drift::Mode::kPredict) {
    throw UsageError(model_path +
                     " is a compensate-mode model: use 'gyrodrift compensate' (predict "
                     "needs a model fitted with --mode predict)");
  }
}

void RequirePredictRate(const io::LoadedModel& loaded, const std::string& model_path,
                        const std::string& log_path, double log_hz, const std::string& how,
                        bool flags) {
  RequireRateOfModel(log_path, log_hz, how, flags, model_path,
                     loaded.model.options.features.rate_hz, [](double ratio) {
                       return fmt::format(
                           "its lags and windows, counted in samples, would span {:.3g} times {} "
                           "time than it learnt",
                           ratio > 1.0 ? ratio : 1.0 / ratio, ratio > 1.0 ? "less" : "more");
                     });
}

PredictResult RunPredict(const io::LoadedModel& loaded, const Eigen::VectorXd& y,
                         const Eigen::VectorXd& temperature, const PredictSettings& settings,
                         const std::string& y_name,
                         std::function<void(double, std::string_view)> progress) {
  settings.Validate();
  const drift::DriftModel& model = loaded.model;
  const drift::Protocol protocol = drift::ProtocolFromString(settings.protocol);
  PredictResult r;
  r.first = drift::FirstPredictable(model, protocol, settings.horizon);
  if (y.size() <= r.first) {
    throw DataError(y_name + " has " + std::to_string(y.size()) +
                    " samples: the model needs more than " + std::to_string(r.first) +
                    " (its history) to predict any");
  }
  const drift::CausalOptions& causal = settings.causal;
  // The threads never change the result.
  const Execution execution{.threads = settings.threads, .progress = std::move(progress)};
  r.prediction = drift::PredictAhead(model, y, temperature, r.first, settings.horizon, protocol,
                                     causal, execution);
  if (protocol == drift::Protocol::kCausal) {
    r.window_note = drift::CausalWindowNote(model, causal);
  }
  return r;
}

nlohmann::json PredictRecord(const PredictResult& r, const io::LoadedModel& loaded,
                             const PredictSettings& s, Eigen::Index samples,
                             const std::string& model_path, const std::string& input) {
  const drift::DriftModel& model = loaded.model;
  nlohmann::json j;
  j["options"] = {{"model", model_path},
                  {"input", input},
                  {"protocol", s.protocol},
                  {"window", s.causal.window},
                  {"mirror", s.causal.mirror},
                  {"windows", s.causal.windows},
                  {"causal_ensemble", s.causal.ensemble_size},
                  {"horizon", s.horizon},
                  {"threads", s.threads}};
  j["model"] = {{"summary", model.Summary()},
                {"method", drift::ToString(model.options.method)},
                {"target_column", loaded.info.target_column},
                {"temperature_column", loaded.info.temperature_column},
                {"lags", model.lags},
                {"seed", model.options.seed},
                {"tool_version", loaded.info.tool_version}};
  j["notes"] = r.window_note.empty() ? nlohmann::json::array()
                                     : nlohmann::json::array({r.window_note});
  j["samples"] = samples;
  j["first_predicted_sample"] = r.first + 1;
  j["predicted"] = samples - r.first;
  return j;
}

}  // namespace gyrodrift::tasks
