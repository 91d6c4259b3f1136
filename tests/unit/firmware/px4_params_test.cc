// The PX4 parameter file: on a family unit's 16-h calibration, the parameters, evaluated as PX4
// evaluates them (its formula, in float), reproduce each axis' autopilot form (AxisAutopilotForm,
// in rad/s) to 1e-6 of the form's range, over temperatures inside and outside the calibrated range
// (PX4 holds T at TMIN and TMAX); the form keeps a measured share of what the full model removes;
// a model with a reference temperature is relative to it; requests PX4 cannot run are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "../../regression/allan/allan_fixtures.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/firmware/export.h"
#include "gyrodrift/io/csv.h"
#include "support/test_support.h"

namespace gyrodrift::firmware {
namespace {

constexpr double kRadsPerDph = std::numbers::pi / 180.0 / 3600.0;

struct Param {
  double value = 0.0;
  int type = 0;
};

std::map<std::string, Param> ParseParams(const std::string& text) {
  std::map<std::string, Param> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream cells(line);
    int vehicle = 0, component = 0;
    std::string name;
    Param p;
    cells >> vehicle >> component >> name >> p.value >> p.type;
    EXPECT_TRUE(cells && vehicle == 1 && component == 1) << line;
    EXPECT_EQ(line.find(' '), std::string::npos) << "tab-separated: " << line;
    out[name] = p;
  }
  return out;
}

// PX4's TemperatureCompensation: dT = clamp(T, TMIN, TMAX) - TREF, then x0 + x1 dT + x2 dT^2 +
// x3 dT^3 with the powers accumulated, every step in float.
float Px4Offset(const std::map<std::string, Param>& p, int gyro, int axis, float t) {
  auto get = [&](const std::string& name) {
    return static_cast<float>(p.at("TC_G" + std::to_string(gyro) + "_" + name).value);
  };
  auto x = [&](int k) { return get("X" + std::to_string(k) + "_" + std::to_string(axis)); };
  const float dt = std::clamp(t, get("TMIN"), get("TMAX")) - get("TREF");
  float power = dt;
  float offset = x(0) + x(1) * power;
  power *= dt;
  offset += x(2) * power;
  power *= dt;
  offset += x(3) * power;
  return offset;
}

// Unit 1's 16-h calibration as a gyro of three axes: x its rate, y minus half of it, z twice it.
std::vector<LoadedModel> ThreeAxes(std::optional<double> reference_c = std::nullopt) {
  const io::CsvTable train = io::CsvTable::Read(allan::fixtures::Gunzip(
      test::TestDataPath("gyro_thermal_family/units/unit1_train16h.csv.gz"), "unit1_train16h"));
  const Eigen::VectorXd rate = train.Column("rate_dph");
  drift::DriftOptions o;
  o.mode = drift::Mode::kCompensate;
  o.method = drift::Method::kThermal;
  o.reference_c = reference_c;
  std::vector<LoadedModel> axes;
  const std::vector<std::pair<std::string, double>> gains{{"x_dph", 1.0}, {"y_dph", -0.5},
                                                          {"z_dph", 2.0}};
  for (const auto& [name, gain] : gains) {
    axes.push_back({drift::FitDriftModel(gain * rate, train.Column("temperature_c"), o),
                    {.target_column = name, .temperature_column = "temperature_c"}});
  }
  return axes;
}

TEST(Px4Params, EvaluatedAsPx4TheyReproduceTheAutopilotForm) {
  const std::vector<LoadedModel> axes = ThreeAxes();
  const std::string text = RenderExport(
      axes, {.format = ExportFormat::kPx4Params, .device_ids = {2490378}});
  const std::map<std::string, Param> p = ParseParams(text);
  EXPECT_EQ(p.at("TC_G_ENABLE").value, 1.0);
  EXPECT_EQ(p.at("TC_G_ENABLE").type, 6);
  EXPECT_EQ(p.at("TC_G0_ID").value, 2490378.0);
  EXPECT_EQ(p.at("TC_G0_X3_2").type, 9);
  EXPECT_EQ(p.size(), 1u + 4u + 12u);
  for (int a = 0; a < 3; ++a) {
    const drift::AutopilotForm form = AxisAutopilotForm(axes[static_cast<size_t>(a)], "axis");
    EXPECT_GE(form.degree, 1) << "unit 1's drift depends on temperature";
    EXPECT_NEAR(p.at("TC_G0_TREF").value, form.tref_c, 1e-5 * std::abs(form.tref_c));
    double range = 0.0, worst = 0.0;
    for (double t = form.tmin_c - 30.0; t <= form.tmax_c + 30.0; t += 0.25) {
      const double expected = form.Estimate(t) * kRadsPerDph;
      range = std::max(range, std::abs(expected));
      worst = std::max(worst, std::abs(Px4Offset(p, 0, a, static_cast<float>(t)) - expected));
    }
    EXPECT_LE(worst, 1e-6 * range) << "axis " << a;
    EXPECT_GT(range, 0.0);
  }
  // The form keeps a measured share of what the full model removes, and says so.
  const drift::AutopilotForm x = AxisAutopilotForm(axes[0], "x");
  EXPECT_TRUE(std::isfinite(x.share_kept));
  EXPECT_NE(x.Summary().find("of the slow drift the full model removes"), std::string::npos)
      << x.Summary();
}

TEST(Px4Params, AModelWithAReferenceTemperatureIsZeroThere) {
  const std::vector<LoadedModel> axes = ThreeAxes(25.0);
  const drift::AutopilotForm form = AxisAutopilotForm(axes[0], "x");
  EXPECT_NEAR(form.Estimate(25.0), 0.0, 1e-12);
  const std::map<std::string, Param> p = ParseParams(
      RenderExport(axes, {.format = ExportFormat::kPx4Params, .device_ids = {7}}));
  EXPECT_NEAR(Px4Offset(p, 0, 0, 25.0f), 0.0, 1e-6 * std::abs(form.Estimate(-5.0)) * kRadsPerDph);
}

TEST(Px4Params, RequestsPx4CannotRunAreRefused) {
  std::vector<LoadedModel> axes = ThreeAxes();
  const ExportOptions px4{.format = ExportFormat::kPx4Params, .device_ids = {1}};
  EXPECT_THROW(RenderExport({axes[0], axes[1]}, px4), UsageError);  // two axes
  EXPECT_THROW(RenderExport(axes, {.format = ExportFormat::kPx4Params, .device_ids = {1, 2}}),
               UsageError);  // three axes for two gyros
  EXPECT_THROW(RenderExport(axes, {.format = ExportFormat::kPx4Params}), OptionError);
  EXPECT_THROW(RenderExport(axes, {.format = ExportFormat::kPx4Params, .device_ids = {0}}),
               OptionError);
  EXPECT_THROW(RenderExport(axes, {.format = ExportFormat::kC, .device_ids = {1}}), OptionError);
  std::vector<LoadedModel> unknown_unit = axes;
  unknown_unit[1].info.rate_unit = "";
  EXPECT_THROW(RenderExport(unknown_unit, px4), UsageError);
  // A model file older than format 8 holds no autopilot form.
  std::vector<LoadedModel> old = axes;
  auto thermal = std::make_shared<drift::ThermalRegression>(*old[2].model.sub_models[0].thermal);
  thermal->autopilot = {};
  old[2].model.sub_models[0].thermal = thermal;
  try {
    RenderExport(old, px4);
    ADD_FAILURE() << "no autopilot form was accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("refit"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gyrodrift::firmware
