// The `predict` user operation, written once for every front end (issue 25): a saved
// predict-mode model's one-step-ahead (or H-step-ahead) predictions of a record, and the record
// its sidecar holds. `gyrodrift predict` and the Python package's DriftModel.predict call these
// and nothing below them.
//
// Cost: drift::PredictAhead's (the causal protocol decomposes CausalOptions::windows trailing
// windows per sample).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::tasks {

struct PredictSettings {
  std::string protocol = "causal";  // drift::Protocol name: causal | paper
  drift::CausalOptions causal;      // the causal protocol's windows
  int horizon = 1;                  // steps ahead, in [1, 100000]
  int threads = 0;                  // [0, 1024]; 0 = every core
  // OptionError naming the field (protocol, causal.window, causal.mirror, causal.windows,
  // causal.ensemble_size, threads).
  void Validate() const;
};

struct PredictResult {
  Eigen::Index first = 0;      // the first predicted sample, 0-based
  Eigen::VectorXd prediction;  // of samples first .. N-1
  std::string window_note;     // drift::CausalWindowNote (causal protocol), or ""
};

// UsageError naming `model_path` unless `loaded` is a predict-mode model.
void RequirePredictMode(const io::LoadedModel& loaded, const std::string& model_path);

// DataError naming the log and the model when the log's sample rate (`log_hz` and `how` from
// io::ResolveSampleRate: --rate-hz or time_s; a rate nobody stated, "default", is not checked) is
// more than 1 % off the model's: the model's lags, decomposition and thermal lags count samples, so
// they would span another stretch of time than the model learnt, silently. `flags`: the rate's
// source spelt as flags (--rate-hz), else as keywords (rate_hz).
void RequirePredictRate(const io::LoadedModel& loaded, const std::string& model_path,
                        const std::string& log_path, double log_hz, const std::string& how,
                        bool flags = true);

// The predictions of `y` (named `y_name` in messages: the log, or "y") by `loaded`, reading
// `temperature` when the model uses it. Throws OptionError (settings), UsageError (a
// compensate-mode model, a missing temperature), DataError (y no longer than the model's history).
PredictResult RunPredict(const io::LoadedModel& loaded, const Eigen::VectorXd& y,
                         const Eigen::VectorXd& temperature, const PredictSettings& settings,
                         const std::string& y_name,
                         std::function<void(double, std::string_view)> progress = {});

// The sidecar (but for its header): the options (with the model and input paths), the model,
// the notes and the counts.
nlohmann::json PredictRecord(const PredictResult& r, const io::LoadedModel& loaded,
                             const PredictSettings& settings, Eigen::Index samples,
                             const std::string& model_path, const std::string& input);

}  // namespace gyrodrift::tasks
