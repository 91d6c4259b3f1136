#include "gyrodrift/simulation/temperature_programme.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

TEST(TemperatureProgramme, ChamberFollowsItsDocumentedSegments) {
  const auto p = BuiltinProgramme("chamber");
  EXPECT_EQ(p.name(), "chamber");
  EXPECT_DOUBLE_EQ(p.NominalDuration(), 8 * 3600.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(0.0), 20.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(30 * 60.0), 20.0);
  EXPECT_NEAR(p.TemperatureAt(50 * 60.0), 40.0, 1e-12);  // halfway up the first ramp
  EXPECT_DOUBLE_EQ(p.TemperatureAt(70 * 60.0), 60.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(160 * 60.0), 60.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(240 * 60.0), -20.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(330 * 60.0), -20.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(370 * 60.0), 20.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(1e6), 20.0);  // held after the end
  EXPECT_NEAR(p.MaxRateKPerS(), 1.0 / 60.0, 1e-15);
}

TEST(TemperatureProgramme, ChamberBIsADifferentEightHourHistory) {
  const auto a = BuiltinProgramme("chamber");
  const auto b = BuiltinProgramme("chamber-b");
  EXPECT_DOUBLE_EQ(b.NominalDuration(), 8 * 3600.0);
  EXPECT_DOUBLE_EQ(b.TemperatureAt(0.0), 25.0);
  EXPECT_DOUBLE_EQ(b.TemperatureAt(60 * 60.0), 45.0);
  EXPECT_DOUBLE_EQ(b.TemperatureAt(180 * 60.0), 0.0);
  EXPECT_NEAR(b.MaxRateKPerS(), 0.75 / 60.0, 1e-15);
  double max_difference = 0.0;
  for (double t = 0; t <= 28800; t += 60) {
    max_difference = std::max(max_difference, std::abs(a.TemperatureAt(t) - b.TemperatureAt(t)));
  }
  EXPECT_GT(max_difference, 20.0);
}

TEST(TemperatureProgramme, SineHasItsAmplitudeAndSlope) {
  const auto s = BuiltinProgramme("sine");
  EXPECT_EQ(s.kind(), TemperatureProgramme::Kind::kSine);
  EXPECT_NEAR(s.TemperatureAt(1800.0), 40.0, 1e-12);
  EXPECT_NEAR(s.TemperatureAt(5400.0), 0.0, 1e-12);
  EXPECT_NEAR(s.MaxRateKPerS(), 2 * M_PI * 20 / 7200, 1e-15);
  // One period is its defined part; a simulation without a duration runs 8 h of it.
  EXPECT_DOUBLE_EQ(s.NominalDuration(), 7200.0);
  EXPECT_DOUBLE_EQ(s.DefaultSimulationDuration(), 8 * 3600.0);
}

TEST(TemperatureProgramme, SamplesAreInterpolatedAndHeld) {
  Eigen::VectorXd t(3), temp(3);
  t << 10, 20, 40;
  temp << 0, 10, -10;
  const auto p = TemperatureProgramme::FromSamples(t, temp, "file.csv");
  EXPECT_DOUBLE_EQ(p.TemperatureAt(0), 0.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(15), 5.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(30), 0.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(100), -10.0);
  EXPECT_DOUBLE_EQ(p.NominalDuration(), 40.0);
  EXPECT_DOUBLE_EQ(p.DefaultSimulationDuration(), 40.0);
  EXPECT_NE(p.Summary().find("file.csv"), std::string::npos);
}

TEST(TemperatureProgramme, BadSamplesAreDataErrors) {
  Eigen::VectorXd t(3), temp(3);
  t << 0, 20, 20;
  temp << 0, 1, 2;
  EXPECT_THROW(TemperatureProgramme::FromSamples(t, temp), DataError);  // not increasing
  t << 0, 10, 20;
  temp << 0, std::numeric_limits<double>::quiet_NaN(), 2;
  EXPECT_THROW(TemperatureProgramme::FromSamples(t, temp), DataError);  // NaN
  temp << 0, 300, 2;
  EXPECT_THROW(TemperatureProgramme::FromSamples(t, temp), DataError);  // Kelvin by mistake
  EXPECT_THROW(TemperatureProgramme::FromSamples(t, Eigen::VectorXd::Zero(2)), DataError);
  EXPECT_THROW(
      TemperatureProgramme::FromSamples(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1)),
      DataError);
}

TEST(TemperatureProgramme, BadSegmentsAndNamesAreUsageErrors) {
  using K = ProgrammeSegment::Kind;
  EXPECT_THROW(TemperatureProgramme::FromSegments(20, {{K::kRamp, -5, 30}}), UsageError);
  EXPECT_THROW(TemperatureProgramme::FromSegments(20, {}), UsageError);
  EXPECT_THROW(TemperatureProgramme::FromSegments(20, {{K::kRamp, 60, 500}}), UsageError);
  EXPECT_THROW(TemperatureProgramme::Sine(20, 20, 0), UsageError);
  try {
    BuiltinProgramme("oven");
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("chamber-b"), std::string::npos);
  }
}

}  // namespace
}  // namespace gyrodrift::simulation
