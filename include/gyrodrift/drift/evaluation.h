// Evaluation that cannot cheat: chronological split, repeats over seeds, and both protocols.
//
// The record is split at floor(split * N): models are fitted on the first block only (under the
// causal protocol the training block is decomposed alone; under the paper protocol the whole
// record is decomposed first and its sub-series split, as the literature does) and scored on the
// second block. Scores are against the truth column when one is given (the simulator's drift),
// else against the measured output. Predict mode: one-step-ahead prediction error. Compensate
// mode: the drift estimate's error (the residual drift left after compensation).
// METHOD.md section 5 explains why both protocols are reported: decomposing before splitting lets
// test-time sub-series see future samples, which alone can explain large gains.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

struct Metrics {
  double rmse = 0.0;
  double mae = 0.0;
  double max_abs = 0.0;
};
Metrics ComputeMetrics(const Eigen::Ref<const Eigen::VectorXd>& error);

// The seed of evaluation repeat r of a fit seeded `seed`: the seed itself for r = 0 (a one-repeat
// evaluation scores the model `fit` writes with that seed), SeedFor(seed, "repeat", r) after.
std::uint64_t RepeatSeed(std::uint64_t seed, int r);

struct EvaluationOptions {
  double split = 0.7;  // training share, in [0.1, 0.95]
  int repeats = 1;     // seeds RepeatSeed(seed, r); mean and std over repeats, in [1, 1000]
  std::vector<Method> methods = AllMethods(Mode::kPredict);
  std::vector<Protocol> protocols{Protocol::kPaper, Protocol::kCausal};
  // Predict mode: score horizon-step-ahead predictions (PredictAhead), in [1, 100000].
  int horizon = 1;
  CausalOptions causal;
  void Validate() const;
  bool operator==(const EvaluationOptions&) const = default;
};

struct EvaluationRow {
  Method method = Method::kMsElm;
  Protocol protocol = Protocol::kPaper;
  double rmse = 0.0, rmse_std = 0.0, mae = 0.0, max_abs = 0.0;  // means over repeats
  double train_s = 0.0, predict_s = 0.0;                        // wall-clock means
  Eigen::VectorXd estimate;  // of the last repeat, on the test block
  std::string model_summary;
  std::vector<std::string> notes;  // causal rows: CausalWindowNote per repeat where it applies
};

struct EvaluationResult {
  Mode mode = Mode::kPredict;
  Eigen::Index split_index = 0;  // first test sample
  bool against_truth = false;
  Eigen::VectorXd reference;        // what the rows were scored against, on the test block
  std::vector<EvaluationRow> rows;  // method-major, protocols in the order asked
  // With a temperature channel: its range on the training block and the share of test samples
  // outside it, where every thermal model extrapolates (NaN, NaN, 0 without temperature).
  double training_temperature_min_c = std::numeric_limits<double>::quiet_NaN();
  double training_temperature_max_c = std::numeric_limits<double>::quiet_NaN();
  double test_outside_training_temperature_share = 0.0;
  std::string Table() const;  // aligned text table
};

// Evaluates options.methods on (y, temperature_c, truth); temperature (N x channels; several only
// for identified compensate-mode models, else a UsageError before any fit) and truth may be
// empty. The training temperature range and the share outside it are of the first channel.
// Fits, decompositions and causal windows run on execution.threads; its progress gets the share
// of the trials done (the causal windows counted within their trial) and a label naming the
// trial, "ms-elm / causal / seed 1" (" / windows" within), then "done". The fits themselves do
// not report. No result depends on the execution but the timings.
EvaluationResult Evaluate(const Eigen::Ref<const Eigen::VectorXd>& y,
                          const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                          const Eigen::Ref<const Eigen::VectorXd>& truth, const DriftOptions& base,
                          const EvaluationOptions& options, const Execution& execution = {});

}  // namespace gyrodrift::drift
