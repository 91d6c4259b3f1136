// Evaluation that cannot cheat: chronological split, repeats over seeds, and both protocols.
//
// The record is split at floor(split * N): models are fitted on the first block only (under the
// causal protocol the training block is decomposed alone; under the paper protocol the whole
// record is decomposed first and its sub-series split, as the literature does) and scored on the
// second block. Scores are against the truth column when one is given (the simulator's drift),
// else against the measured output; with a truth, each row is also scored against the measured
// output (predict mode: the measured sample predicted). Predict mode: the (horizon-step-ahead)
// prediction error. Compensate mode: the drift estimate's error (the residual drift left after
// compensation). Every evaluation scores the references none (a zero estimate: doing nothing)
// and constant (the training mean) first, and gives every row the share of the slow variation
// (SlowVariation) it removes, so that a method worse than doing nothing shows as such.
// METHOD.md section 5 explains why both protocols are reported: decomposing before splitting lets
// test-time sub-series see future samples, which alone can explain large gains.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

struct Metrics {
  double rmse = 0.0;
  double mae = 0.0;
  double max_abs = 0.0;
};
Metrics ComputeMetrics(const Eigen::Ref<const Eigen::VectorXd>& error);

// The slow variation of a series x sampled at rate_hz: the RMS about zero of its means over whole
// blocks of block_s seconds (default 10 min, compensation_summary.h), from the first sample on (a
// last partial block is left out); NaN when x is shorter than one block. It keeps the bias and
// the slow drift, which a calibration is meant to remove, and leaves little of the
// sample-to-sample noise (white noise of sd s contributes s / sqrt(samples per block)). (The
// compensation summary reports the block means' RMS about their mean beside the mean itself.)
double SlowVariation(const Eigen::Ref<const Eigen::VectorXd>& x, double rate_hz,
                     double block_s = kSlowVariationBlockS);

// The share of the slow variation of `reference` an estimate removes: 1 - SlowVariation(reference
// - estimate) / SlowVariation(reference). 0 for a zero estimate, 1 for a perfect one, negative for
// an estimate that adds slow error; NaN when the series are shorter than one block or the
// reference has no slow variation.
double SlowVariationRemoved(const Eigen::Ref<const Eigen::VectorXd>& reference,
                            const Eigen::Ref<const Eigen::VectorXd>& estimate, double rate_hz,
                            double block_s = kSlowVariationBlockS);

// The seed of evaluation repeat r of a fit seeded `seed`: the seed itself for r = 0 (a one-repeat
// evaluation scores the model `fit` writes with that seed), SeedFor(seed, "repeat", r) after.
std::uint64_t RepeatSeed(std::uint64_t seed, int r);

struct EvaluationOptions {
  double split = 0.7;  // training share, in [0.1, 0.95]
  int repeats = 1;     // seeds RepeatSeed(seed, r); mean and std over repeats, in [1, 1000]
  // The methods scored after the references ReferenceMethods(), which are always scored first (a
  // reference named here too is scored once, first).
  std::vector<Method> methods = AllMethods(Mode::kPredict);
  std::vector<Protocol> protocols{Protocol::kPaper, Protocol::kCausal};
  // Predict mode: score horizon-step-ahead predictions (PredictAhead), in [1, 100000].
  int horizon = 1;
  CausalOptions causal;
  void Validate() const;
  bool operator==(const EvaluationOptions&) const = default;
};

// The methods an evaluation scores, in the order of its rows: ReferenceMethods(), then
// options.methods without them.
std::vector<Method> EvaluatedMethods(const EvaluationOptions& options);

struct EvaluationRow {
  Method method = Method::kMsElm;
  Protocol protocol = Protocol::kPaper;
  double rmse = 0.0, rmse_std = 0.0, mae = 0.0, max_abs = 0.0;  // means over repeats
  // Means over repeats: the RMSE against the measured output (rmse itself without a truth), and
  // the share of the reference's slow variation removed (SlowVariationRemoved; NaN for a test
  // block shorter than 10 min).
  double rmse_measured = 0.0, slow_removed = 0.0;
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
  // Method-major (the references none and constant first), protocols in the order asked.
  std::vector<EvaluationRow> rows;
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
