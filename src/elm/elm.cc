#include "gyrodrift/elm/elm.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "common/enum_names.h"
#include "elm/elm_kernels.h"
#include "elm/training.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::elm {
namespace {

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;

constexpr std::array<std::pair<Activation, std::string_view>, 5> kActivations{{
    {Activation::kSigmoid, "sigmoid"},
    {Activation::kTanh, "tanh"},
    {Activation::kSine, "sine"},
    {Activation::kRbf, "rbf"},
    {Activation::kLinear, "linear"},
}};
constexpr std::array<std::pair<Solver, std::string_view>, 2> kSolvers{{
    {Solver::kCholesky, "cholesky"},
    {Solver::kQr, "qr"},
}};
constexpr std::array<std::pair<Selection, std::string_view>, 2> kSelections{{
    {Selection::kFixed, "fixed"},
    {Selection::kAuto, "auto"},
}};

std::string FormatShort(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

void RequireFiniteMatrix(std::string_view what, const Eigen::Ref<const Eigen::MatrixXd>& m) {
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      if (!std::isfinite(m(i, j))) {
        throw DataError(std::string(what) + " row " + std::to_string(i + 1) + " column " +
                        std::to_string(j + 1) + " is " + FormatValue(m(i, j)) +
                        ": every value must be finite");
      }
    }
  }
}

void CheckTrainingData(const Eigen::Ref<const Eigen::MatrixXd>& x,
                       const Eigen::Ref<const Eigen::MatrixXd>& t) {
  if (x.rows() != t.rows()) {
    throw DataError("inputs have " + std::to_string(x.rows()) + " rows but targets have " +
                    std::to_string(t.rows()) + ": the row counts must match");
  }
  if (x.rows() < 2) {
    throw DataError("training data has " + std::to_string(x.rows()) +
                    " rows: at least 2 are needed");
  }
  if (x.cols() < 1) throw DataError("inputs have no columns: at least 1 is needed");
  if (t.cols() < 1) throw DataError("targets have no columns: at least 1 is needed");
  RequireFiniteMatrix("inputs", x);
  RequireFiniteMatrix("targets", t);
}

// Streams the model's hidden layer over fixed row blocks on `threads` workers; body(r0, rows, h)
// runs once per block with h = H[r0 : r0 + rows, :].
template <class Body>
void ForEachHiddenBlock(const ElmModel& model, const Eigen::MatrixXd& xs, int threads,
                        const Body& body) {
  const Eigen::Index n = xs.rows();
  const int blocks = internal::NumBlocks(n);
  if (blocks == 0) return;
  const int workers = std::min(ResolveThreads(threads), blocks);
  std::vector<Eigen::MatrixXd> buffer(
      static_cast<size_t>(workers),
      Eigen::MatrixXd(std::min(n, internal::kBlockRows), model.num_hidden()));
  ParallelFor(blocks, workers, [&](int block, int worker) {
    const Eigen::Index r0 = block * internal::kBlockRows;
    const Eigen::Index rows = std::min(internal::kBlockRows, n - r0);
    auto h = buffer[static_cast<size_t>(worker)].topRows(rows);
    internal::ComputeHidden(model.activation, xs.middleRows(r0, rows), model.input_weights,
                            model.biases, h);
    body(r0, rows, h);
  });
}

// Output weights by Householder QR: [H; I/sqrt(C)] beta = [T; 0], or the minimum-norm least
// squares solution of H beta = T when C is infinite. Stores H (N x L).
void SolveQr(ElmModel* model, const Eigen::MatrixXd& xs, const Eigen::MatrixXd& ts, int threads,
             ElmReport* report) {
  const Eigen::Index n = xs.rows();
  const Eigen::Index hidden = model->num_hidden();
  const bool ridge = std::isfinite(model->options.ridge_c);
  Eigen::MatrixXd stacked(ridge ? n + hidden : n, hidden);
  ForEachHiddenBlock(*model, xs, threads, [&](Eigen::Index r0, Eigen::Index rows, const auto& h) {
    stacked.middleRows(r0, rows) = h;
  });
  Eigen::MatrixXd h_copy;
  Eigen::VectorXd diag;
  if (ridge) {
    // The residual needs H itself; the factorisation overwrites `stacked`.
    h_copy = stacked.topRows(n);
    stacked.bottomRows(hidden).setZero();
    stacked.bottomRows(hidden).diagonal().setConstant(1.0 / std::sqrt(model->options.ridge_c));
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + hidden, ts.cols());
    rhs.topRows(n) = ts;
    Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(stacked);
    model->output_weights = qr.solve(rhs);
    diag = qr.matrixQR().diagonal().cwiseAbs();
    report->numerical_rank = static_cast<int>(hidden);
  } else {
    h_copy = stacked;
    Eigen::CompleteOrthogonalDecomposition<Eigen::Ref<Eigen::MatrixXd>> cod(stacked);
    model->output_weights = cod.solve(ts);
    report->numerical_rank = static_cast<int>(cod.rank());
    diag = cod.matrixQTZ().diagonal().head(cod.rank()).cwiseAbs();
  }
  report->condition_estimate = diag.size() > 0 && diag.minCoeff() > 0.0
                                   ? diag.maxCoeff() / diag.minCoeff()
                                   : std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd residual = h_copy * model->output_weights - ts;
  const Eigen::RowVectorXd sse = residual.colwise().squaredNorm();
  report->train_rmse = std::sqrt((sse.array() * model->target_scaler.scale.array().square()).sum() /
                                 (static_cast<double>(n) * static_cast<double>(ts.cols())));
}

// Training RMSE in target units from the normal equations (no second pass over the rows).
double TrainRmseFromGram(const internal::Gram& gram, const Eigen::MatrixXd& beta,
                         const Eigen::MatrixXd& ts, const Eigen::RowVectorXd& target_scale) {
  const Eigen::Index l = beta.rows();
  const Eigen::MatrixXd g_beta =
      gram.hth.topLeftCorner(l, l).selfadjointView<Eigen::Lower>() * beta;
  const Eigen::RowVectorXd tt = ts.colwise().squaredNorm();
  const Eigen::RowVectorXd cross = beta.cwiseProduct(gram.htt.topRows(l)).colwise().sum();
  const Eigen::RowVectorXd quad = beta.cwiseProduct(g_beta).colwise().sum();
  const Eigen::ArrayXd sse = (tt - 2.0 * cross + quad).array().max(0.0).transpose();
  return std::sqrt((sse * target_scale.transpose().array().square()).sum() /
                   (static_cast<double>(ts.rows()) * static_cast<double>(ts.cols())));
}

}  // namespace

std::string_view ToString(Activation activation) { return EnumName(activation, kActivations); }
Activation ActivationFromString(std::string_view name) {
  return EnumFromName(name, "activation", kActivations);
}
std::string_view ToString(Solver solver) { return EnumName(solver, kSolvers); }
Solver SolverFromString(std::string_view name) { return EnumFromName(name, "solver", kSolvers); }
std::string_view ToString(Selection selection) { return EnumName(selection, kSelections); }
Selection SelectionFromString(std::string_view name) {
  return EnumFromName(name, "selection", kSelections);
}

void ElmOptions::Validate() const {
  if (hidden_units < 1 || hidden_units > kMaxHiddenUnits) {
    ThrowOption("hidden_units", std::to_string(hidden_units),
                "an integer in [1, " + std::to_string(kMaxHiddenUnits) + "]");
  }
  if (!(ridge_c > 0.0)) {  // also rejects NaN
    ThrowOption("ridge_c", FormatValue(ridge_c), "> 0 (inf = no regularisation, solver qr)");
  }
  if (std::isinf(ridge_c) && selection == Selection::kFixed && solver != Solver::kQr) {
    ThrowOption("ridge_c", FormatValue(ridge_c),
                "finite with solver = cholesky (use solver = qr for C = inf)");
  }
  for (int l : hidden_unit_candidates) {
    if (l < 1 || l > hidden_units) {
      ThrowOption("hidden_unit_candidates", std::to_string(l),
                  "in [1, hidden_units = " + std::to_string(hidden_units) + "]");
    }
  }
  for (double c : ridge_c_candidates) {
    if (!(c > 0.0) || !std::isfinite(c)) {
      ThrowOption("ridge_c_candidates", FormatValue(c), "finite and > 0");
    }
  }
  if (!(max_condition >= 1e3 && max_condition <= 1e15)) {
    ThrowOption("max_condition", FormatValue(max_condition), "in [1e3, 1e15]");
  }
}

std::vector<int> ElmOptions::HiddenUnitGrid() const {
  std::vector<int> grid = hidden_unit_candidates;
  if (grid.empty()) {
    for (long decade = 1; decade < hidden_units; decade *= 10) {
      for (long step : {1L, 2L, 5L}) {
        if (decade * step < hidden_units) grid.push_back(static_cast<int>(decade * step));
      }
    }
    grid.push_back(hidden_units);
  }
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

std::vector<double> ElmOptions::RidgeGrid() const {
  std::vector<double> grid = ridge_c_candidates;
  if (grid.empty()) {
    for (int e = -2; e <= 10; ++e) grid.push_back(std::pow(10.0, e));
  }
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

Eigen::MatrixXd Standardizer::Apply(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  return ((x.rowwise() - mean).array().rowwise() / scale.array()).matrix();
}

Eigen::MatrixXd Standardizer::Invert(const Eigen::Ref<const Eigen::MatrixXd>& x_s) const {
  return (x_s.array().rowwise() * scale.array()).matrix().rowwise() + mean;
}

Standardizer FitStandardizer(const Eigen::Ref<const Eigen::MatrixXd>& x, bool enabled) {
  Standardizer s;
  s.mean = Eigen::RowVectorXd::Zero(x.cols());
  s.scale = Eigen::RowVectorXd::Ones(x.cols());
  if (!enabled || x.rows() == 0) return s;
  s.mean = x.colwise().mean();
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    const double sd = std::sqrt((x.col(j).array() - s.mean[j]).square().mean());
    // A column constant up to rounding carries no information; dividing by its rounding noise
    // would blow the noise up, so it is only centred.
    const double rounding = 64.0 * std::numeric_limits<double>::epsilon() * std::abs(s.mean[j]);
    s.scale[j] = sd > rounding && sd > 0.0 ? sd : 1.0;
  }
  return s;
}

void ElmModel::Validate() const {
  const Eigen::Index d = input_weights.rows();
  const Eigen::Index l = input_weights.cols();
  const Eigen::Index m = output_weights.cols();
  auto fail = [](const std::string& what) { throw DataError("ELM model: " + what); };
  if (d < 1 || l < 1 || m < 1) fail("empty input weights or output weights");
  if (biases.size() != l) {
    fail(std::to_string(biases.size()) + " biases for " + std::to_string(l) + " hidden units");
  }
  if (output_weights.rows() != l) {
    fail(std::to_string(output_weights.rows()) + " output weight rows for " + std::to_string(l) +
         " hidden units");
  }
  if (input_scaler.mean.size() != d || input_scaler.scale.size() != d) {
    fail("input scaler has " + std::to_string(input_scaler.mean.size()) + " columns for " +
         std::to_string(d) + " inputs");
  }
  if (target_scaler.mean.size() != m || target_scaler.scale.size() != m) {
    fail("target scaler has " + std::to_string(target_scaler.mean.size()) + " columns for " +
         std::to_string(m) + " outputs");
  }
  if (!input_weights.allFinite() || !biases.allFinite() || !output_weights.allFinite() ||
      !input_scaler.mean.allFinite() || !target_scaler.mean.allFinite()) {
    fail("a weight, bias or scaler mean is not finite");
  }
  if (!(input_scaler.scale.array() > 0.0).all() || !(target_scaler.scale.array() > 0.0).all() ||
      !input_scaler.scale.allFinite() || !target_scaler.scale.allFinite()) {
    fail("a scaler scale is not a finite number > 0");
  }
}

std::string ElmReport::Summary() const {
  std::string s = "elm: L=" + std::to_string(hidden_units) + " C=" + FormatShort(ridge_c) + " " +
                  std::string(ToString(solver)) + ", " + std::to_string(rows) +
                  " rows, train RMSE " + FormatShort(train_rmse) + ", cond " +
                  FormatShort(condition_estimate);
  if (ldlt_fallback) s += " (LDLT fallback)";
  if (solver == Solver::kQr && numerical_rank < hidden_units) {
    s += ", rank " + std::to_string(numerical_rank);
  }
  if (selection == Selection::kAuto) {
    int evaluated = 0;
    for (const auto& c : candidates) evaluated += c.skipped ? 0 : 1;
    s += ", auto: LOO RMSE " + FormatShort(loo_rmse) + " best of " + std::to_string(evaluated) +
         " (L, C) pairs (" + std::to_string(candidates.size() - evaluated) + " ill-conditioned)";
  }
  s += ", seed " + std::to_string(seed);
  return s;
}

namespace {

// selection = auto: draws the largest candidate's units, scores every (L, C) pair by its
// leave-one-out error (report->candidates) and keeps the best pair's units in *model (its
// options' hidden_units and ridge_c set to the pair). Returns the Gram matrix of all the units
// drawn, whose leading block the refit reuses.
internal::Gram SelectByLoo(const ElmOptions& options, const Eigen::MatrixXd& xs,
                           const Eigen::MatrixXd& ts, int threads, ElmModel* model,
                           ElmReport* report) {
  const std::vector<int> hidden_grid = options.HiddenUnitGrid();
  const std::vector<double> ridge_grid = options.RidgeGrid();
  internal::DrawUnits(static_cast<int>(xs.cols()), hidden_grid.back(), options.seed,
                      &model->input_weights, &model->biases);
  internal::Gram gram = internal::ComputeGram(options.activation, xs, ts, model->input_weights,
                                              model->biases, threads);
  internal::LooGrid(options.activation, xs, ts, model->input_weights, model->biases, gram,
                    hidden_grid, ridge_grid, options.max_condition, model->target_scaler.scale,
                    threads, &report->candidates);
  const LooCandidate* best = nullptr;
  for (const auto& c : report->candidates) {
    // Ties (to the bit) go to the smaller network, then the stronger regularisation.
    if (!c.skipped && std::isfinite(c.loo_mse) &&
        (best == nullptr || c.loo_mse < best->loo_mse)) {
      best = &c;
    }
  }
  if (best == nullptr) {
    throw DataError(
        "ELM auto selection: every (L, C) pair has cond(H^T H + I/C) above "
        "max_condition = " +
        FormatValue(options.max_condition) +
        " or an undefined leave-one-out error; add smaller C candidates");
  }
  report->loo_rmse = best->loo_rmse;
  model->input_weights.conservativeResize(Eigen::NoChange, best->hidden_units);
  model->biases.conservativeResize(best->hidden_units);
  model->options.hidden_units = best->hidden_units;
  model->options.ridge_c = best->ridge_c;
  return gram;
}

}  // namespace

ElmFit Fit(const Eigen::Ref<const Eigen::MatrixXd>& x, const Eigen::Ref<const Eigen::MatrixXd>& t,
           const ElmOptions& options, const Execution& execution) {
  options.Validate();
  execution.Validate();
  const int threads = execution.threads;
  CheckTrainingData(x, t);
  const Eigen::Index n = x.rows();

  ElmFit fit;
  ElmModel& model = fit.model;
  ElmReport& report = fit.report;
  model.activation = options.activation;
  model.options = options;
  model.input_scaler = FitStandardizer(x, options.standardize_inputs);
  model.target_scaler = FitStandardizer(t, options.standardize_targets);
  const Eigen::MatrixXd xs = model.input_scaler.Apply(x);
  const Eigen::MatrixXd ts = model.target_scaler.Apply(t);

  report.selection = options.selection;
  report.solver = options.solver;
  report.rows = static_cast<int>(n);
  report.seed = options.seed;
  report.threads = std::min(ResolveThreads(threads), internal::NumBlocks(n));

  int hidden = options.hidden_units;
  double ridge_c = options.ridge_c;
  internal::Gram gram;
  bool have_gram = false;
  if (options.selection == Selection::kAuto) {
    gram = SelectByLoo(options, xs, ts, threads, &model, &report);
    have_gram = true;
    hidden = model.options.hidden_units;
    ridge_c = model.options.ridge_c;
  } else {
    internal::DrawUnits(static_cast<int>(x.cols()), hidden, options.seed, &model.input_weights,
                        &model.biases);
  }
  report.hidden_units = hidden;
  report.ridge_c = ridge_c;
  report.numerical_rank = hidden;

  if (options.solver == Solver::kQr) {
    SolveQr(&model, xs, ts, threads, &report);
    return fit;
  }
  if (!have_gram) {
    gram = internal::ComputeGram(options.activation, xs, ts, model.input_weights, model.biases,
                                 threads);
  }
  internal::RidgeSolution solution =
      internal::SolveRidgeCholesky(gram.hth, gram.htt, hidden, ridge_c);
  model.output_weights = std::move(solution.beta);
  report.condition_estimate = solution.condition;
  report.ldlt_fallback = solution.ldlt_fallback;
  report.train_rmse = TrainRmseFromGram(gram, model.output_weights, ts, model.target_scaler.scale);
  return fit;
}

namespace {

// The model and the inputs checked (shape, finite values), then standardised with the model's
// training-time scaler: what Predict and HiddenLayer both start from.
Eigen::MatrixXd CheckedScaledInputs(const ElmModel& model,
                                    const Eigen::Ref<const Eigen::MatrixXd>& x) {
  model.Validate();
  if (x.cols() != model.num_inputs()) {
    throw DataError("inputs have " + std::to_string(x.cols()) + " columns but the ELM model has " +
                    std::to_string(model.num_inputs()) + " inputs");
  }
  RequireFiniteMatrix("inputs", x);
  return model.input_scaler.Apply(x);
}

}  // namespace

std::string_view KernelName() { return internal::ActiveKernels().name; }

Eigen::MatrixXd HiddenLayer(const ElmModel& model, const Eigen::Ref<const Eigen::MatrixXd>& x,
                            int threads) {
  ValidateThreads(threads);
  const Eigen::MatrixXd xs = CheckedScaledInputs(model, x);
  Eigen::MatrixXd h(x.rows(), model.num_hidden());
  ForEachHiddenBlock(model, xs, threads,
                     [&](Eigen::Index r0, Eigen::Index rows, const auto& block) {
                       h.middleRows(r0, rows) = block;
                     });
  return h;
}

Eigen::MatrixXd Predict(const ElmModel& model, const Eigen::Ref<const Eigen::MatrixXd>& x,
                        int threads) {
  ValidateThreads(threads);
  const Eigen::MatrixXd xs = CheckedScaledInputs(model, x);
  Eigen::MatrixXd y(x.rows(), model.num_outputs());
  const internal::Kernels& kernels = internal::ActiveKernels();
  ForEachHiddenBlock(model, xs, threads, [&](Eigen::Index r0, Eigen::Index rows, const auto& h) {
    // The kernel sums each output over the units in one fixed order, so a row predicted alone
    // gets the same bits as in any batch.
    kernels.output(h.data(), h.outerStride(), rows, model.num_hidden(), model.output_weights.data(),
                   model.num_outputs(), y.data() + r0, y.outerStride());
  });
  return model.target_scaler.Invert(y);
}

}  // namespace gyrodrift::elm
