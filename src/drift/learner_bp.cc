// kBp: a fully connected multilayer perceptron trained by FANN (Nissen 2003) with RPROP
// (Riedmiller & Braun 1993; FANN_TRAIN_RPROP is iRPROP-, Igel & Huesken 2000), batch mode.
//
// Layer k: a_k = f_k(clamp(s_k * (W_k [a_{k-1}; 1]))), f = tanh for hidden layers (FANN's
// SIGMOID_SYMMETRIC, 2 / (1 + exp(-2 u)) - 1, steepness s = 0.5), identity for the output
// (steepness 1); clamp to +-150 / s as fann_run does. Inputs and target are standardised on
// the training rows; the training error is FANN's linear MSE in standardised units.
// Initial weights: W_k(i, j) ~ U[-r, r], r = sqrt(3 / (n_{k-1} + 1)) (unit-variance net input
// for unit-variance inputs), drawn row by row from Rng(seed, k) and written into FANN's weight
// array, so a seed reproduces the network; fann_randomize_weights (rand()) is not used.
// Caveat: fann_create_standard_array itself reseeds the C library's rand() (from
// /dev/urandom) and draws its own initial weights, which are overwritten. Nothing in gyrodrift
// uses rand(); the result does not depend on it.
// After training the weights are copied out; prediction (right after training and after
// LoadLearner) is the forward pass below, not fann_run: one code path, so a saved network
// predicts the same bits, loading needs no FANN object, and Predict is thread-safe (fann_run
// writes into the network). It agrees with fann_run to rounding (FANN sums in another order).
// FANN prints errors to stderr by default: the error log is switched off, and training calls
// fann_train_epoch directly (fann_train_on_data prints progress reports).
#include <doublefann.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "drift/learner_kinds.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::drift::internal {
namespace {

constexpr double kHiddenSteepness = 0.5;  // FANN's default
constexpr double kOutputSteepness = 1.0;  // a plain linear output

void SilenceFann() {
  static std::once_flag once;
  // Networks copy the default log when they are created; NULL means no output.
  std::call_once(once, [] { fann_set_error_log(nullptr, nullptr); });
}

struct FannDeleter {
  void operator()(struct fann* ann) const { fann_destroy(ann); }
};
struct FannDataDeleter {
  void operator()(struct fann_train_data* data) const { fann_destroy_train(data); }
};

double Activate(double u, double steepness, bool hidden) {
  double s = steepness * u;
  const double max_sum = 150.0 / steepness;
  s = std::clamp(s, -max_sum, max_sum);
  return hidden ? 2.0 / (1.0 + std::exp(-2.0 * s)) - 1.0 : s;
}

// Calls body(k, t, j, weight_index) for every connection of layer k (1-based), neuron t to
// input j of the previous layer (j = n_{k-1} is its bias neuron).
template <class Body>
void ForEachConnection(struct fann* ann, const std::vector<int>& sizes, const Body& body) {
  const int layers = static_cast<int>(sizes.size());
  for (int k = 1; k < layers; ++k) {
    const fann_layer* layer = ann->first_layer + k;
    const fann_layer* prev = layer - 1;
    int t = 0;
    for (const fann_neuron* neuron = layer->first_neuron; neuron != layer->last_neuron; ++neuron) {
      if (neuron->first_con == neuron->last_con) continue;  // a bias neuron
      for (unsigned int c = neuron->first_con; c < neuron->last_con; ++c) {
        const long j = ann->connections[c] - prev->first_neuron;
        body(k, t, static_cast<int>(j), c);
      }
      ++t;
    }
  }
}

class BpLearner final : public Learner {
 public:
  BpLearner(std::vector<int> sizes, std::vector<Eigen::MatrixXd> weights,
            elm::Standardizer input_scaler, elm::Standardizer target_scaler, std::uint64_t seed)
      : sizes_(std::move(sizes)),
        weights_(std::move(weights)),
        input_scaler_(std::move(input_scaler)),
        target_scaler_(std::move(target_scaler)),
        seed_(seed) {}

  LearnerKind kind() const override { return LearnerKind::kBp; }
  int num_inputs() const override { return sizes_.front(); }

  Eigen::VectorXd Predict(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    CheckPredictInput(kind(), num_inputs(), x);
    const Eigen::MatrixXd z = input_scaler_.Apply(x);
    const int widest = *std::max_element(sizes_.begin(), sizes_.end());
    std::vector<double> in(static_cast<size_t>(widest));
    std::vector<double> out(static_cast<size_t>(widest));
    const int layers = static_cast<int>(sizes_.size());
    Eigen::VectorXd y(x.rows());
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      for (int j = 0; j < sizes_[0]; ++j) in[static_cast<size_t>(j)] = z(i, j);
      for (int k = 1; k < layers; ++k) {
        const Eigen::MatrixXd& w = weights_[static_cast<size_t>(k - 1)];
        const int n_in = sizes_[static_cast<size_t>(k - 1)];
        const bool hidden = k + 1 < layers;
        for (int t = 0; t < sizes_[static_cast<size_t>(k)]; ++t) {
          double u = 0.0;
          for (int j = 0; j < n_in; ++j) u += w(t, j) * in[static_cast<size_t>(j)];
          u += w(t, n_in);  // bias neuron, value 1
          out[static_cast<size_t>(t)] =
              Activate(u, hidden ? kHiddenSteepness : kOutputSteepness, hidden);
        }
        std::swap(in, out);
      }
      y[i] = in[0] * target_scaler_.scale[0] + target_scaler_.mean[0];
    }
    return y;
  }

  Parameters Save() const override {
    Parameters p;
    PutCommon(kind(), seed_, rows_, train_rmse_, &p);
    Eigen::RowVectorXd sizes(static_cast<Eigen::Index>(sizes_.size()));
    for (size_t k = 0; k < sizes_.size(); ++k) sizes[static_cast<Eigen::Index>(k)] = sizes_[k];
    p.arrays["layer_sizes"] = sizes;
    for (size_t k = 0; k < weights_.size(); ++k) {
      p.arrays["weights_" + std::to_string(k + 1)] = weights_[k];
    }
    PutScaler("input", input_scaler_, &p);
    PutScaler("target", target_scaler_, &p);
    p.scalars["epochs"] = epochs_;
    p.scalars["train_mse"] = train_mse_;
    return p;
  }

  std::string Summary() const override {
    std::string layers;
    long count = 0;
    for (size_t k = 0; k < sizes_.size(); ++k) {
      layers += (k ? "-" : "") + std::to_string(sizes_[k]);
      if (k) count += static_cast<long>(sizes_[k]) * (sizes_[k - 1] + 1);
    }
    return "bp: " + std::to_string(num_inputs()) + " inputs, layers " + layers + " (" +
           std::to_string(count) + " weights), RPROP " + std::to_string(epochs_) + " epochs (MSE " +
           FormatShort(train_mse_) + "), " + std::to_string(rows_) + " rows, train RMSE " +
           FormatShort(train_rmse_) + ", seed " + std::to_string(seed_);
  }

  void SetTraining(int rows, double train_rmse, int epochs, double train_mse) {
    rows_ = rows;
    train_rmse_ = train_rmse;
    epochs_ = epochs;
    train_mse_ = train_mse;
  }

 private:
  std::vector<int> sizes_;                // d, hidden..., 1
  std::vector<Eigen::MatrixXd> weights_;  // layer k: n_k x (n_{k-1} + 1), bias last
  elm::Standardizer input_scaler_;
  elm::Standardizer target_scaler_;
  std::uint64_t seed_;
  int rows_ = 0;
  double train_rmse_ = 0.0;
  int epochs_ = 0;
  double train_mse_ = 0.0;
};

}  // namespace

std::unique_ptr<Learner> FitBp(const Eigen::Ref<const Eigen::MatrixXd>& x,
                               const Eigen::Ref<const Eigen::VectorXd>& y,
                               const LearnerOptions& options) {
  SilenceFann();
  const Eigen::Index n = x.rows();
  const int d = static_cast<int>(x.cols());
  elm::Standardizer input_scaler = elm::FitStandardizer(x, true);
  elm::Standardizer target_scaler = elm::FitStandardizer(y, true);
  const Eigen::MatrixXd z = input_scaler.Apply(x);
  const Eigen::VectorXd ys = target_scaler.Apply(y);

  std::vector<int> sizes{d};
  sizes.insert(sizes.end(), options.bp_hidden.begin(), options.bp_hidden.end());
  sizes.push_back(1);
  std::vector<unsigned int> layer_sizes(sizes.begin(), sizes.end());
  std::vector<Eigen::MatrixXd> weights;
  for (size_t k = 1; k < sizes.size(); ++k) {
    const int n_in = sizes[k - 1];
    Eigen::MatrixXd w(sizes[k], n_in + 1);
    Rng rng(options.seed, k);
    const double r = std::sqrt(3.0 / (n_in + 1));
    for (Eigen::Index t = 0; t < w.rows(); ++t) {
      for (Eigen::Index j = 0; j < w.cols(); ++j) w(t, j) = rng.Uniform(-r, r);
    }
    weights.push_back(std::move(w));
  }

  std::unique_ptr<struct fann, FannDeleter> ann(fann_create_standard_array(
      static_cast<unsigned int>(layer_sizes.size()), layer_sizes.data()));
  if (!ann) throw DataError("bp: FANN could not create the network (out of memory?)");
  fann_set_error_log(reinterpret_cast<struct fann_error*>(ann.get()), nullptr);
  fann_set_activation_function_hidden(ann.get(), FANN_SIGMOID_SYMMETRIC);
  fann_set_activation_function_output(ann.get(), FANN_LINEAR);
  fann_set_activation_steepness_hidden(ann.get(), kHiddenSteepness);
  fann_set_activation_steepness_output(ann.get(), kOutputSteepness);
  fann_set_training_algorithm(ann.get(), FANN_TRAIN_RPROP);
  // FANN's default TANH error function distorts the error of a linear output.
  fann_set_train_error_function(ann.get(), FANN_ERRORFUNC_LINEAR);
  long connections = 0;
  ForEachConnection(ann.get(), sizes, [&](int k, int t, int j, unsigned int c) {
    ann->weights[c] = weights[static_cast<size_t>(k - 1)](t, j);
    ++connections;
  });
  long expected = 0;
  for (const auto& w : weights) expected += static_cast<long>(w.size());
  if (connections != expected || fann_get_total_connections(ann.get()) != expected) {
    throw std::logic_error("bp: FANN network layout is not the fully connected one expected");
  }

  std::unique_ptr<struct fann_train_data, FannDataDeleter> data(
      fann_create_train(static_cast<unsigned int>(n), static_cast<unsigned int>(d), 1));
  if (!data) throw DataError("bp: FANN could not allocate the training data (out of memory?)");
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int j = 0; j < d; ++j) data->input[i][j] = z(i, j);
    data->output[i][0] = ys[i];
  }
  int epochs = 0;
  double mse = 0.0;
  while (epochs < options.bp_epochs) {
    // The MSE of the weights before this epoch's update (FANN accumulates it on the way).
    mse = fann_train_epoch(ann.get(), data.get());
    ++epochs;
    if (mse <= options.bp_desired_mse) break;
  }
  ForEachConnection(ann.get(), sizes, [&](int k, int t, int j, unsigned int c) {
    weights[static_cast<size_t>(k - 1)](t, j) = ann->weights[c];
  });
  for (const auto& w : weights) {
    if (!w.allFinite()) {
      throw DataError("bp: RPROP training diverged after " + std::to_string(epochs) +
                      " epochs (a weight is not finite); try fewer epochs or smaller layers");
    }
  }

  auto learner =
      std::make_unique<BpLearner>(std::move(sizes), std::move(weights), std::move(input_scaler),
                                  std::move(target_scaler), options.seed);
  learner->SetTraining(static_cast<int>(n), Rmse(learner->Predict(x), y), epochs, mse);
  return learner;
}

std::unique_ptr<Learner> LoadBp(const ParameterReader& reader) {
  const Eigen::MatrixXd& sizes_array = reader.Array("layer_sizes", 1, -1);
  const Eigen::Index layers = sizes_array.cols();
  if (layers < 3 || layers > 5) {
    reader.Fail("layer_sizes has " + std::to_string(layers) +
                " entries, expected 3 to 5 (inputs, 1 to 3 hidden layers, output)");
  }
  std::vector<int> sizes;
  for (Eigen::Index k = 0; k < layers; ++k) {
    const double v = sizes_array(0, k);
    if (!(v >= 1.0 && v <= 100000.0) || v != std::floor(v)) {
      reader.Fail("layer_sizes entry " + std::to_string(k + 1) + " = " + FormatShort(v) +
                  " is not a positive integer");
    }
    sizes.push_back(static_cast<int>(v));
  }
  if (sizes.back() != 1) reader.Fail("layer_sizes must end with 1 output");
  std::vector<Eigen::MatrixXd> weights;
  for (Eigen::Index k = 1; k < layers; ++k) {
    weights.push_back(reader.Array("weights_" + std::to_string(k), sizes[static_cast<size_t>(k)],
                                   sizes[static_cast<size_t>(k - 1)] + 1));
  }
  elm::Standardizer input_scaler = GetScaler(reader, "input", sizes.front());
  elm::Standardizer target_scaler = GetScaler(reader, "target", 1);
  auto learner =
      std::make_unique<BpLearner>(std::move(sizes), std::move(weights), std::move(input_scaler),
                                  std::move(target_scaler), reader.Seed());
  learner->SetTraining(
      static_cast<int>(reader.Integer("train_rows", 0, 2147483647L)), reader.Scalar("train_rmse"),
      static_cast<int>(reader.Integer("epochs", 0, 100000)), reader.Scalar("train_mse"));
  return learner;
}

}  // namespace gyrodrift::drift::internal
