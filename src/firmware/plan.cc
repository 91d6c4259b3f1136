#include "plan.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/features.h"

namespace gyrodrift::firmware {
namespace internal {

std::vector<std::string> SplitNames(const std::string& names) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = names.find(',', start);
    out.push_back(names.substr(start, comma == std::string::npos ? comma : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::string AxisLabel(size_t i, const LoadedModel& m) {
  return fmt::format("axis {} ({})", i, m.info.target_column);
}

namespace {

// Model channel -> plan channel for the temperature columns `names`, adding those the plan lacks.
std::vector<int> MapChannels(const std::vector<std::string>& names, Plan& plan) {
  std::vector<int> global;
  for (const std::string& name : names) {
    const auto at = std::find(plan.channels.begin(), plan.channels.end(), name);
    global.push_back(static_cast<int>(at - plan.channels.begin()));
    if (at == plan.channels.end()) plan.channels.push_back(name);
  }
  return global;
}

// The lag state ts of t on plan channel `channel`, its coefficients read from k on (k advanced);
// its chain (one per channel and time constant) found or added.
State PlanState(const drift::ThermalRegression& t, const drift::ThermalState& ts, int channel,
                Eigen::Index& k, Plan& plan) {
  const auto cu = static_cast<size_t>(ts.channel);
  const double dt_s = 1.0 / t.rate_hz;  // as ThermalRegression::Regressors
  // Axes share a chain only at the same gain: rates that agree to RequireExportable's tolerance
  // still give each model its own (the gain of its own rate, as its fit).
  const double gain = drift::FirstOrderLagGain(ts.tau_s, dt_s);
  auto chain = std::find_if(plan.chains.begin(), plan.chains.end(), [&](const Chain& c) {
    return c.channel == channel && c.tau_s == ts.tau_s && c.gain == gain;
  });
  if (chain == plan.chains.end()) {
    plan.chains.push_back({channel, ts.tau_s, dt_s, gain, 0, 0});
    chain = plan.chains.end() - 1;
  }
  chain->stages = std::max(chain->stages, t.order);
  State state;
  state.chain = static_cast<int>(chain - plan.chains.begin());
  state.order = t.order;
  state.centre_c = t.centre_c[cu];
  state.scale_k = t.scale_k[cu];
  state.level_min = ts.level_min;
  state.level_max = ts.level_max;
  for (int p = 1; p <= t.max_power; ++p) state.powers.push_back(t.coefficients[k++]);
  state.rate = t.coefficients[k++];
  state.rate_min = ts.rate_min;
  state.rate_max = ts.rate_max;
  state.rate_beyond = ts.rate_beyond;
  return state;
}

// The sub-model of thermal regression t, its channels mapped by `global`: the intercept, the
// static powers, the lag states and the hysteresis term, in the order of t's coefficients; with
// its estimate at equilibrium at reference_c unless that is NaN.
Sub PlanSub(const std::string& name, const drift::ThermalRegression& t,
            const std::vector<int>& global, double reference_c, Plan& plan) {
  Sub s;
  s.name = name;
  if (plan.rate_hz == 0.0) plan.rate_hz = t.rate_hz;  // the first axis's; each chain keeps its own
  Eigen::Index k = 0;
  s.intercept = t.coefficients[k++];
  for (int c = 0; c < t.channels(); ++c) {
    const auto cu = static_cast<size_t>(c);
    if (t.static_power[cu] == 0) continue;
    Static st{global[cu], t.centre_c[cu], t.scale_k[cu], t.static_min[cu], t.static_max[cu], {}};
    for (int p = 1; p <= t.static_power[cu]; ++p) st.powers.push_back(t.coefficients[k++]);
    s.statics.push_back(std::move(st));
  }
  for (const drift::ThermalState& ts : t.states) {
    s.states.push_back(PlanState(t, ts, global[static_cast<size_t>(ts.channel)], k, plan));
    ++plan.states;
  }
  if (t.has_hysteresis()) {
    s.hysteresis = {t.hysteresis_state, plan.plays++, t.hysteresis_width_k, t.coefficients[k++]};
  }
  if (!std::isnan(reference_c)) {
    // The library's own estimate of a record in equilibrium at the reference.
    s.reference_estimate = t.Estimate(Eigen::MatrixXd::Constant(1, t.channels(), reference_c))[0];
  }
  return s;
}

}  // namespace

void RequireDistinctAxes(const std::vector<LoadedModel>& axes) {
  for (size_t a = 0; a < axes.size(); ++a) {
    for (size_t b = 0; b < a; ++b) {
      if (axes[a].info.target_column != axes[b].info.target_column) continue;
      for (const std::string& channel : SplitNames(axes[a].info.temperature_column)) {
        const std::vector<std::string> other = SplitNames(axes[b].info.temperature_column);
        if (std::find(other.begin(), other.end(), channel) == other.end()) continue;
        throw UsageError(fmt::format(
            "{} has the target and the temperature column '{}' of axis {}: two gyros logged "
            "alike, whose channels the export would join by name, so that both read one sensor; "
            "fit each gyro under its own column names, or export each on its own with its own "
            "prefix",
            AxisLabel(a, axes[a]), channel, b));
      }
    }
  }
}

Plan MakePlan(const std::vector<LoadedModel>& axes) {
  RequireExportable(axes);
  Plan plan;
  for (const LoadedModel& loaded : axes) {
    const drift::DriftModel& model = loaded.model;
    const std::vector<int> global = MapChannels(SplitNames(loaded.info.temperature_column), plan);
    Axis axis;
    axis.name = loaded.info.target_column;
    axis.summary = model.Summary();
    axis.source = loaded.info.source;
    axis.method = drift::ToString(model.options.method);
    axis.reference_c = model.options.reference_c.value_or(std::numeric_limits<double>::quiet_NaN());
    for (const drift::SubModel& sub : model.sub_models) {
      if (sub.thermal) {
        axis.subs.push_back(PlanSub(sub.name, *sub.thermal, global, axis.reference_c, plan));
      } else {
        Sub s;
        s.name = sub.name;
        s.zero = true;
        axis.subs.push_back(std::move(s));
      }
    }
    plan.axes.push_back(std::move(axis));
  }
  for (Chain& c : plan.chains) {
    c.first = plan.lag_stages;
    plan.lag_stages += c.stages;
  }
  if (plan.rate_hz == 0.0) plan.rate_hz = axes[0].model.options.features.rate_hz;
  return plan;
}

}  // namespace internal

using internal::AxisLabel;
using internal::SplitNames;

void RequireExportable(const std::vector<LoadedModel>& axes) {
  if (axes.empty()) throw UsageError("export needs at least one model (one per gyro axis)");
  double rate_hz = 0.0;
  for (size_t a = 0; a < axes.size(); ++a) {
    const drift::DriftModel& model = axes[a].model;
    const std::string axis = AxisLabel(a, axes[a]);
    if (model.options.mode != drift::Mode::kCompensate) {
      throw UsageError(axis +
                       " is a predict-mode model: firmware runs compensate-mode models, which "
                       "need only temperature (fit in mode compensate)");
    }
    for (const drift::SubModel& sub : model.sub_models) {
      if (sub.baseline) {
        throw UsageError(fmt::format(
            "{} is a {} model, a reference for evaluation: export takes method thermal, ms-elm or "
            "emd-elm",
            axis, drift::ToString(model.options.method)));
      }
      if (sub.learner) {
        throw UsageError(fmt::format(
            "{}: sub-model '{}' is a {} learner on thermal features, not an identified thermal "
            "model: export takes method thermal, ms-elm or emd-elm",
            axis, sub.name, drift::ToString(model.options.method)));
      }
      if (!sub.thermal) continue;
      if (sub.thermal->correction) {
        throw UsageError(fmt::format(
            "{}: sub-model '{}' has a nonlinear correction (linear_compensation = false), whose "
            "sigmoid units need exp at every sample: refit linear to export",
            axis, sub.name));
      }
      // One logger's rate read from two logs' time stamps differs in its last digits; each lag
      // chain takes its gain from its own model's rate (PlanState), so only a real difference
      // is refused.
      if (rate_hz != 0.0 && std::abs(sub.thermal->rate_hz / rate_hz - 1.0) > 1e-6) {
        throw UsageError(fmt::format(
            "{} was fitted at {} Hz, an earlier axis at {} Hz: one step function serves every "
            "axis, so their models need one sample rate",
            axis, sub.thermal->rate_hz, rate_hz));
      }
      rate_hz = sub.thermal->rate_hz;
    }
    const size_t names = SplitNames(axes[a].info.temperature_column).size();
    if (axes[a].info.temperature_column.empty() ||
        static_cast<int>(names) != model.temperature_channels()) {
      throw DataError(fmt::format(
          "{}: the model takes {} temperature channel(s), its file names {}", axis,
          model.temperature_channels(), axes[a].info.temperature_column.empty() ? 0 : names));
    }
  }
}

}  // namespace gyrodrift::firmware
