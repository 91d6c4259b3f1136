// The plausibility check of a temperature column (temperature_check.h): degC passes; ADC counts,
// kelvin and whole-number steps are named with what the tool assumes.
#include "gyrodrift/drift/temperature_check.h"

#include <gtest/gtest.h>

#include <cmath>

namespace gyrodrift::drift {
namespace {

TEST(TemperatureCheck, DegreesCelsiusPass) {
  EXPECT_EQ(TemperatureWarning(Eigen::VectorXd::LinSpaced(100, -40.0, 85.3), "t"), "");
  // A plateau sensor with two whole-degree levels, and a constant: too few values to call steps.
  EXPECT_EQ(TemperatureWarning(Eigen::Vector4d(20, 20, 45, 45), "t"), "");
  EXPECT_EQ(TemperatureWarning(Eigen::VectorXd::Constant(5, 25.0), "t"), "");
  // Non-finite samples are for the caller to refuse, not this check.
  EXPECT_EQ(TemperatureWarning(Eigen::Vector3d(std::nan(""), 20.5, 21.5), "t"), "");
  EXPECT_EQ(TemperatureWarning(Eigen::VectorXd(), "t"), "");
}

TEST(TemperatureCheck, CountsKelvinAndWholeStepsAreNamed) {
  // A BMI270-like register: about 64,000 counts, whole numbers.
  const std::string counts =
      TemperatureWarning(Eigen::Vector3d(63990, 64000, 64117), "temp_raw");
  EXPECT_EQ(counts,
            "temperature column 'temp_raw' runs from 63990 to 64117, outside -80..200 degC; "
            "whole numbers only: raw ADC counts?; it is taken as degC as given (ramps, dwells, "
            "rates in K/min and the reference temperature read it so): convert it to degC");
  EXPECT_NE(TemperatureWarning(Eigen::Vector3d(293.15, 300.2, 310.7), "t").find("kelvin?"),
            std::string::npos);
  EXPECT_NE(TemperatureWarning(Eigen::Vector2d(-90.5, 20.5), "t").find("outside -80..200 degC"),
            std::string::npos);
  // Whole numbers inside the range, stepping: named, with the quantisation it implies.
  const std::string steps = TemperatureWarning(Eigen::Vector4d(20, 21, 22, 23), "t");
  EXPECT_NE(steps.find("whole numbers only (20 to 23)"), std::string::npos) << steps;
  EXPECT_NE(steps.find("taken as degC as given"), std::string::npos) << steps;
}

}  // namespace
}  // namespace gyrodrift::drift
