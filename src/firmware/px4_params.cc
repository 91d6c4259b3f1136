// The PX4 parameter file of export.h: each gyro instance's autopilot forms (thermal_model.h
// AutopilotForm), in rad/s, as the parameters of PX4's thermal compensation (docs/firmware.md,
// "PX4"), in the tab-separated form QGroundControl loads.
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/version.h"
#include "plan.h"

namespace gyrodrift::firmware {
namespace {

// PX4 calibrates at most three gyros (TC_G0_* .. TC_G2_*), each as three axes.
constexpr size_t kMostInstances = 3;
constexpr size_t kAxes = 3;
// MAV_PARAM_TYPE of the file's last column.
constexpr int kInt32 = 6, kReal32 = 9;

// rad/s per unit of the model's estimates.
double RadsPer(const LoadedModel& axis, const std::string& label) {
  if (axis.info.rate_unit.empty()) {
    throw UsageError(label + ": the model file does not say the unit of its target (written before "
                             "format 4): refit it to export for PX4, which runs in rad/s");
  }
  return allan::ToDegPerHour(allan::RateUnitFromString(axis.info.rate_unit)) * std::numbers::pi /
         180.0 / 3600.0;
}

std::string Line(const std::string& name, double value) {
  return fmt::format("1\t1\t{}\t{:.9g}\t{}\n", name, static_cast<float>(value), kReal32);
}

std::string Line(const std::string& name, std::int32_t value) {
  return fmt::format("1\t1\t{}\t{}\t{}\n", name, value, kInt32);
}

}  // namespace

drift::AutopilotForm AxisAutopilotForm(const LoadedModel& axis, const std::string& label) {
  const drift::DriftModel& model = axis.model;
  drift::AutopilotForm form;
  int forms = 0;
  for (const drift::SubModel& sub : model.sub_models) {
    if (!sub.thermal) continue;
    const drift::AutopilotForm& f = sub.thermal->autopilot;
    if (!f.fitted()) {
      throw UsageError(label + ": the model has no autopilot form (written before format 8): "
                               "refit it to export for PX4");
    }
    if (forms++ == 0) {
      form = f;
      continue;
    }
    // Every sub-model saw the same temperatures, so their ranges agree; the sum's share of the
    // full model is not measured.
    for (size_t k = 0; k < form.coefficients.size(); ++k) form.coefficients[k] += f.coefficients[k];
    form.degree = std::max(form.degree, f.degree);
    form.share_kept = std::numeric_limits<double>::quiet_NaN();
  }
  if (forms == 0) {
    throw UsageError(label + ": PX4 runs a cubic in temperature, which only a compensate-mode "
                             "model of method thermal, ms-elm or emd-elm carries");
  }
  // As the full model (drift::EstimateDrift): relative to equilibrium at the reference.
  if (model.options.reference_c) form.coefficients[0] -= form.Estimate(*model.options.reference_c);
  return form;
}

std::string RenderPx4Params(const std::vector<LoadedModel>& axes,
                            const std::vector<std::uint32_t>& device_ids) {
  return MakePx4Params(axes, device_ids).text;
}

Px4Params MakePx4Params(const std::vector<LoadedModel>& axes,
                        const std::vector<std::uint32_t>& device_ids) {
  const size_t instances = device_ids.size();
  if (instances == 0 || instances > kMostInstances || axes.size() != kAxes * instances) {
    throw UsageError(fmt::format(
        "px4: {} ax{} for {} device id{}: PX4 calibrates 1 to {} gyros of 3 axes each (x, y, z, "
        "in that order: fit -t x_dph,y_dph,z_dph), one device id each",
        axes.size(), axes.size() == 1 ? "is" : "es", instances, instances == 1 ? "" : "s",
        kMostInstances));
  }
  Px4Params result;
  std::string& out = result.text;
  out = fmt::format(
      "# PX4 thermal compensation of {} gyro{} (TC_G*), written by gyrodrift {}\n"
      "# offset = X0 + X1 dT + X2 dT^2 + X3 dT^3, dT = clamp(T, TMIN, TMAX) - TREF, rad/s, "
      "subtracted from the gyro\n#\n# Vehicle-Id Component-Id Name Value Type\n",
      instances, instances == 1 ? "" : "s", kVersion);
  out += Line("TC_G_ENABLE", std::int32_t{1});
  for (size_t i = 0; i < instances; ++i) {
    const std::string g = fmt::format("TC_G{}_", i);
    out += Line(g + "ID", static_cast<std::int32_t>(device_ids[i]));
    std::array<drift::AutopilotForm, kAxes> forms;
    for (size_t a = 0; a < kAxes; ++a) {
      const LoadedModel& axis = axes[kAxes * i + a];
      const std::string label = internal::AxisLabel(kAxes * i + a, axis);
      forms[a] = AxisAutopilotForm(axis, label);
      result.forms.push_back({fmt::format("TC_G{} axis {} ({})", i, a, axis.info.target_column),
                              forms[a]});
      const double scale = RadsPer(axis, label);
      for (double& c : forms[a].coefficients) c *= scale;
      if (forms[a].tmin_c != forms[0].tmin_c || forms[a].tmax_c != forms[0].tmax_c) {
        throw UsageError(fmt::format(
            "px4: {} was calibrated over [{:g}, {:g}] degC, the gyro's x axis over [{:g}, {:g}]: "
            "PX4 holds one range per gyro (fit its three axes together)",
            label, forms[a].tmin_c, forms[a].tmax_c, forms[0].tmin_c, forms[0].tmax_c));
      }
    }
    out += Line(g + "TMAX", forms[0].tmax_c);
    out += Line(g + "TMIN", forms[0].tmin_c);
    out += Line(g + "TREF", forms[0].tref_c);
    for (size_t k = 0; k < 4; ++k) {
      for (size_t a = 0; a < kAxes; ++a) {
        out += Line(fmt::format("{}X{}_{}", g, k, a), forms[a].coefficients[k]);
      }
    }
  }
  return result;
}

}  // namespace gyrodrift::firmware
