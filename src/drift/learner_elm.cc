// kElm: an adapter over elm::Fit / elm::Predict. The saved state is the whole ElmModel, so a
// loaded learner runs the very same Predict on the very same numbers.
#include <cmath>
#include <utility>

#include "drift/learner_kinds.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::drift::internal {
namespace {

class ElmLearner final : public Learner {
 public:
  ElmLearner(elm::ElmModel model, int rows, double train_rmse)
      : model_(std::move(model)), rows_(rows), train_rmse_(train_rmse) {}

  LearnerKind kind() const override { return LearnerKind::kElm; }
  int num_inputs() const override { return model_.num_inputs(); }

  Eigen::VectorXd Predict(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    CheckPredictInput(kind(), num_inputs(), x);
    return elm::Predict(model_, x).col(0);
  }

  Parameters Save() const override {
    Parameters p;
    PutCommon(kind(), model_.options.seed, rows_, train_rmse_, &p);
    p.arrays["input_weights"] = model_.input_weights;
    p.arrays["biases"] = model_.biases;
    p.arrays["output_weights"] = model_.output_weights;
    PutScaler("input", model_.input_scaler, &p);
    PutScaler("target", model_.target_scaler, &p);
    p.texts["activation"] = std::string(elm::ToString(model_.activation));
    p.texts["solver"] = std::string(elm::ToString(model_.options.solver));
    p.texts["selection"] = std::string(elm::ToString(model_.options.selection));
    p.scalars["hidden_units"] = model_.num_hidden();
    // May be +inf (QR solver without regularisation); it is informational for prediction.
    p.scalars["ridge_c"] = model_.options.ridge_c;
    return p;
  }

  std::string Summary() const override {
    return "elm: " + std::to_string(num_inputs()) +
           " inputs, L=" + std::to_string(model_.num_hidden()) + " " +
           std::string(elm::ToString(model_.activation)) +
           " C=" + FormatShort(model_.options.ridge_c) + " (" +
           std::string(elm::ToString(model_.options.selection)) + "), " + std::to_string(rows_) +
           " rows, train RMSE " + FormatShort(train_rmse_) + ", seed " +
           std::to_string(model_.options.seed);
  }

 private:
  elm::ElmModel model_;
  int rows_;
  double train_rmse_;
};

}  // namespace

std::unique_ptr<Learner> FitElm(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const LearnerOptions& options, int threads) {
  elm::ElmOptions elm_options = options.elm;
  elm_options.seed = options.seed;
  elm::ElmFit fit = elm::Fit(x, y, elm_options, Execution{.threads = threads});
  return std::make_unique<ElmLearner>(std::move(fit.model), static_cast<int>(x.rows()),
                                      fit.report.train_rmse);
}

std::unique_ptr<Learner> LoadElm(const ParameterReader& reader) {
  elm::ElmModel model;
  const Eigen::MatrixXd& input_weights = reader.Array("input_weights", -1, -1);
  const Eigen::Index d = input_weights.rows();
  const Eigen::Index l = input_weights.cols();
  model.input_weights = input_weights;
  model.biases = reader.Array("biases", l, 1);
  model.output_weights = reader.Array("output_weights", l, 1);
  model.input_scaler = GetScaler(reader, "input", d);
  model.target_scaler = GetScaler(reader, "target", 1);
  try {
    model.activation = elm::ActivationFromString(reader.Text("activation"));
    model.options.solver = elm::SolverFromString(reader.Text("solver"));
    model.options.selection = elm::SelectionFromString(reader.Text("selection"));
  } catch (const UsageError& e) {
    reader.Fail(e.what());
  }
  model.options.activation = model.activation;
  if (reader.Integer("hidden_units", 1, elm::kMaxHiddenUnits) != l) {
    reader.Fail("hidden_units = " + FormatShort(reader.Scalar("hidden_units")) + " but " +
                "input_weights has " + std::to_string(l) + " columns");
  }
  model.options.hidden_units = static_cast<int>(l);
  const double ridge_c = reader.Scalar("ridge_c");
  if (!(ridge_c > 0.0)) reader.Fail("ridge_c = " + FormatShort(ridge_c) + " is not > 0");
  model.options.ridge_c = ridge_c;
  reader.DropLegacyThreads();
  model.options.seed = reader.Seed();
  model.Validate();
  const int rows = static_cast<int>(reader.Integer("train_rows", 0, 2147483647L));
  return std::make_unique<ElmLearner>(std::move(model), rows, reader.Scalar("train_rmse"));
}

}  // namespace gyrodrift::drift::internal
