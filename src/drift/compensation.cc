// Compensate mode at run time: the drift estimate of a fitted model from temperature alone
// (EstimateDrift, EstimateDriftWithSd with the identified sub-models' bands), and the share of a
// temperature record outside the training range (ShareOutsideRange), where it extrapolates.
#include <cmath>
#include <limits>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

double ShareOutsideRange(const Eigen::Ref<const Eigen::VectorXd>& temperature_c, double min_c,
                         double max_c) {
  if (!(min_c <= max_c) || temperature_c.size() == 0) return 0.0;
  const auto outside = (temperature_c.array() < min_c) || (temperature_c.array() > max_c);
  return static_cast<double>(outside.count()) / static_cast<double>(temperature_c.size());
}

Eigen::MatrixXd EstimateDriftWithSd(const DriftModel& model,
                                    const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                                    const std::vector<Eigen::Index>& record_starts) {
  if (model.options.mode != Mode::kCompensate) {
    throw UsageError(
        "model mode = predict: drift estimation needs a model fitted in mode compensate");
  }
  if (!record_starts.empty()) {
    // Every record on its own: each starts in equilibrium at its first temperature.
    CheckRecordStarts(record_starts, temperature_c.rows());
    Eigen::MatrixXd out(temperature_c.rows(), 2);
    ForEachRecord(temperature_c.rows(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      out.middleRows(begin, length) =
          EstimateDriftWithSd(model, temperature_c.middleRows(begin, length));
    });
    return out;
  }
  const Eigen::Index n = temperature_c.rows();
  if (temperature_c.cols() != model.temperature_channels()) {
    throw DataError("the model takes " + std::to_string(model.temperature_channels()) +
                    " temperature channel(s), " + std::to_string(temperature_c.cols()) +
                    " given");
  }
  // Equilibrium at the reference: a one-sample record starts (and stays) in equilibrium.
  const bool referenced = model.options.reference_c.has_value();
  const Eigen::MatrixXd t_ref =
      Eigen::MatrixXd::Constant(1, temperature_c.cols(), model.options.reference_c.value_or(0.0));
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, 2);
  bool every_band = true;
  Eigen::MatrixXd f;
  Eigen::MatrixXd f_ref;
  for (const auto& sub : model.sub_models) {
    if (sub.thermal) {
      const Eigen::MatrixXd e = sub.thermal->EstimateWithSd(temperature_c);
      out.col(0) += e.col(0);
      out.col(1) += e.col(1).cwiseAbs2();
      if (referenced) out.col(0).array() -= sub.thermal->Estimate(t_ref)[0];
      continue;
    }
    every_band = false;
    if (sub.baseline) {
      // none or constant: no temperature dependence, so nothing is left relative to a reference.
      if (!referenced && sub.baseline->method == Method::kConstant) {
        out.col(0).array() += sub.baseline->constant;
      }
      continue;
    }
    if (!sub.learner) continue;
    if (f.size() == 0) {
      const FeatureOptions features = EffectiveFeatures(model.options);
      f = ThermalFeatures(temperature_c.col(0), features);
      if (referenced) f_ref = ThermalFeatures(t_ref.col(0), features);
    }
    out.col(0) += sub.learner->Predict(f);
    if (referenced) out.col(0).array() -= sub.learner->Predict(f_ref)[0];
  }
  if (every_band) {
    out.col(1) = out.col(1).cwiseSqrt();
  } else {
    out.col(1).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

Eigen::VectorXd EstimateDrift(const DriftModel& model,
                              const Eigen::Ref<const Eigen::MatrixXd>& temperature_c,
                              const std::vector<Eigen::Index>& record_starts) {
  return EstimateDriftWithSd(model, temperature_c, record_starts).col(0);
}
}  // namespace gyrodrift::drift
