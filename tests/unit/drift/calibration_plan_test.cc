// gyrodrift plan's programme (calibration_plan.h): ramps both ways at two rates, dwells at three
// levels, the length asked; refused with what would fit when the range and rate cannot be held.
// Followed by the simulator and fitted, the run has every regime the fit asks for.
#include "gyrodrift/drift/calibration_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/thermal_model.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"

namespace gyrodrift::drift {
namespace {

TEST(CalibrationPlan, BothDirectionsAtTwoRatesAndThreeLevels) {
  const CalibrationPlan plan = PlanCalibration({.hours = 8.0, .min_c = -20.0, .max_c = 60.0});
  ASSERT_EQ(plan.steps.size(), 8u);
  EXPECT_DOUBLE_EQ(plan.steps.back().end_s, 8.0 * 3600.0);
  std::set<double> heating, cooling, levels;
  for (const PlanStep& s : plan.steps) {
    const double rate = (s.to_c - s.from_c) / (s.end_s - s.start_s) * 60.0;
    if (rate > 0) heating.insert(std::round(rate * 100.0));
    if (rate < 0) cooling.insert(std::round(-rate * 100.0));
    if (rate == 0) {
      levels.insert(s.to_c);
      EXPECT_GE(s.end_s - s.start_s, 80.0 * 60.0);
    }
  }
  EXPECT_EQ(heating.size(), 2u);
  EXPECT_EQ(cooling.size(), 2u);
  EXPECT_EQ(levels, (std::set<double>{-20.0, 20.0, 60.0}));
  EXPECT_EQ(plan.time_s.size(), plan.steps.size() + 1);
  EXPECT_TRUE(plan.warnings.empty());
  // 1.5 K/min: the rate that leaves 80-min dwells in 8 h over 80 K.
  EXPECT_DOUBLE_EQ(plan.rate_k_per_min, 1.5);
}

TEST(CalibrationPlan, TooShortIsRefusedWithWhatWouldFit) {
  try {
    PlanCalibration({.hours = 4.0, .min_c = -40.0, .max_c = 80.0});
    ADD_FAILURE() << "a 4-h plan over 120 K was accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("it needs 8.4 h or more"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PlanCalibration({.hours = 8.0, .min_c = 20.0, .max_c = 25.0}), OptionError);
  EXPECT_THROW(PlanCalibration({.rate_k_per_min = 5.0}), OptionError);
  // Short but feasible: the fit's slowest state cannot reach a coil's lag, and the plan says so.
  const CalibrationPlan short_plan =
      PlanCalibration({.hours = 4.0, .min_c = 0.0, .max_c = 40.0, .shortest_dwell_min = 30.0});
  ASSERT_EQ(short_plan.warnings.size(), 1u);
  EXPECT_NE(short_plan.warnings[0].find("lag by"), std::string::npos) << short_plan.warnings[0];
}

TEST(CalibrationPlan, FollowedByTheSimulatorItIdentifiesWithoutAWarning) {
  const CalibrationPlan plan = PlanCalibration({});
  const auto n = static_cast<Eigen::Index>(plan.time_s.size());
  const simulation::SimulationResult log = simulation::Simulate(
      simulation::TemperatureProgramme::FromSamples(
          Eigen::Map<const Eigen::VectorXd>(plan.time_s.data(), n),
          Eigen::Map<const Eigen::VectorXd>(plan.temperature_c.data(), n), "plan"),
      simulation::PresetParameters(simulation::Preset::kNavigation),
      {.duration_s = plan.time_s.back(), .seed = 2});
  const ThermalRegression m =
      IdentifyThermalModel(log.temperature_c, log.rate_dph, 1.0, ThermalModelOptions{});
  std::string said;
  for (const std::string& w : m.report.warnings) said += "warning: " + w + "\n";
  for (const std::string& a : m.report.advice) said += "advice: " + a + "\n";
  EXPECT_EQ(said, "");
  EXPECT_EQ(m.report.ramps, 4);
  EXPECT_EQ(m.report.dwells, 4);
}

TEST(CalibrationPlan, ARunAtOneRateIsAdvisedASecond) {
  // The built-in chamber programme: 1 K/min both ways.
  const simulation::SimulationResult log =
      simulation::Simulate(simulation::BuiltinProgramme("chamber"),
                           simulation::PresetParameters(simulation::Preset::kNavigation),
                           {.seed = 2});
  const ThermalRegression m =
      IdentifyThermalModel(log.temperature_c, log.rate_dph, 1.0, ThermalModelOptions{});
  std::string advice;
  for (const std::string& a : m.report.advice) advice += a + "\n";
  EXPECT_NE(advice.find("heating at one rate"), std::string::npos) << advice;
  EXPECT_NE(advice.find("cooling at one rate"), std::string::npos) << advice;
}

}  // namespace
}  // namespace gyrodrift::drift
