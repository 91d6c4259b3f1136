#include "gyrodrift/simulation/coil_thermal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

constexpr double kPi = std::numbers::pi;

// Fixed-temperature faces: a film conductance far above k / dr.
ThermalParameters DirichletParams(ThermalScheme scheme) {
  ThermalParameters p;
  p.inner_conductance_w_m2k = 1e9;
  p.outer_conductance_w_m2k = 1e9;
  p.scheme = scheme;
  return p;
}

TEST(LagStep, IsExactForALinearInput) {
  const double tau = 1200.0, slope = 1.0 / 60.0;
  double x = 0.0;
  for (int i = 0; i < 3600; ++i) x = LagStep(x, slope * i, slope * (i + 1), 1.0, tau);
  const double t = 3600.0;
  EXPECT_NEAR(x, slope * (t - tau * (1.0 - std::exp(-t / tau))), 1e-10);
  // One long step gives the same state as many short ones.
  EXPECT_NEAR(LagStep(0.0, 0.0, slope * t, t, tau), x, 1e-10);
}

TEST(RadialConduction, SteadyStateMatchesTheRobinCylinderSolution) {
  ThermalParameters p;  // h_in = 3, h_out = 8, k = 0.25
  const double r1 = 0.046, r2 = 0.054, k = p.conductivity_w_mk;
  const double h1 = p.inner_conductance_w_m2k, h2 = p.outer_conductance_w_m2k;
  const RadialConduction pack(r1, r2, 32, p);
  const double t1 = -10.0, t2 = 30.0;
  const Eigen::VectorXd t = pack.SteadyState(t1, t2);
  // Series resistances per unit height and radian: film, log conduction, film.
  const double q = (t2 - t1) / (1.0 / (h1 * r1) + std::log(r2 / r1) / k + 1.0 / (h2 * r2));
  for (int i = 0; i < pack.cells(); ++i) {
    const double r = pack.cell_radius_m()[i];
    const double exact = t1 + q * (1.0 / (h1 * r1) + std::log(r / r1) / k);
    EXPECT_NEAR(t[i], exact, 1e-4 * (t2 - t1)) << "ring " << i;
  }
}

TEST(RadialConduction, SteadyStateWithFixedFacesIsTheLogProfile) {
  const double r1 = 0.02, r2 = 0.04;  // a thick pack, so curvature matters
  const RadialConduction pack(r1, r2, 200, DirichletParams(ThermalScheme::kBackwardEuler));
  const Eigen::VectorXd t = pack.SteadyState(0.0, 1.0);
  for (int i = 0; i < pack.cells(); i += 7) {
    const double r = pack.cell_radius_m()[i];
    EXPECT_NEAR(t[i], std::log(r / r1) / std::log(r2 / r1), 2e-5) << "ring " << i;
  }
}

// A thin shell at a large radius is a slab; after a step of both faces to 0 from 1 the
// temperature is sum_{n odd} 4 / (n pi) sin(n pi x / w) exp(-n^2 pi^2 a t / w^2)
// (Carslaw & Jaeger sec. 3.3).
double SlabStepResponse(double x, double t, double w, double a) {
  double sum = 0.0;
  for (int n = 1; n < 400; n += 2) {
    sum += 4.0 / (n * kPi) * std::sin(n * kPi * x / w) *
           std::exp(-n * n * kPi * kPi * a * t / (w * w));
  }
  return sum;
}

class SlabTest : public ::testing::TestWithParam<ThermalScheme> {};

TEST_P(SlabTest, StepResponseMatchesTheSeries) {
  const ThermalParameters p = DirichletParams(GetParam());
  const double w = 0.01, r1 = 1e6, a = p.diffusivity_m2_s;
  const int cells = 100;
  RadialConduction pack(r1, r1 + w, cells, p);
  pack.SetUniform(1.0);
  // Crank-Nicolson needs steps near the cell time dr^2/a = 0.067 s to damp the step's sharp modes.
  const double h = GetParam() == ThermalScheme::kBackwardEuler ? 0.002 : 0.01;
  double t = 0.0;
  for (const double check : {10.0, 30.0, 60.0, 120.0}) {
    const int steps = static_cast<int>(std::lround((check - t) / h));
    for (int s = 0; s < steps; ++s) pack.Step(h, 0.0, 0.0, 0.0, 0.0);
    t = check;
    double max_error = 0.0;
    for (int i = 0; i < cells; ++i) {
      const double x = (i + 0.5) * w / cells;
      max_error =
          std::max(max_error, std::abs(pack.temperature_c()[i] - SlabStepResponse(x, t, w, a)));
    }
    EXPECT_LT(max_error, 2e-3) << "t = " << t;
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, SlabTest,
                         ::testing::Values(ThermalScheme::kBackwardEuler,
                                           ThermalScheme::kCrankNicolson),
                         [](const auto& info) {
                           return info.param == ThermalScheme::kBackwardEuler ? "BackwardEuler"
                                                                              : "CrankNicolson";
                         });

// Time-step error of the first slab mode sin(pi x / w), which decays as exp(-pi^2 a t / w^2):
// halving the step halves it for backward Euler and quarters it for Crank-Nicolson.
double FirstModeError(ThermalScheme scheme, double h) {
  const ThermalParameters p = DirichletParams(scheme);
  const double w = 0.01, r1 = 1e6;
  const int cells = 50;
  RadialConduction pack(r1, r1 + w, cells, p);
  Eigen::VectorXd init(cells);
  for (int i = 0; i < cells; ++i) init[i] = std::sin(kPi * (i + 0.5) / cells);
  pack.SetTemperatures(init);
  RadialConduction fine = pack;
  for (int s = 0; s < static_cast<int>(std::lround(60.0 / h)); ++s) pack.Step(h, 0, 0, 0, 0);
  for (int s = 0; s < 60000; ++s) fine.Step(0.001, 0, 0, 0, 0);  // time-converged reference
  return (pack.temperature_c() - fine.temperature_c()).cwiseAbs().maxCoeff();
}

TEST(RadialConduction, BackwardEulerIsFirstAndCrankNicolsonSecondOrderInTime) {
  const double be = FirstModeError(ThermalScheme::kBackwardEuler, 4.0) /
                    FirstModeError(ThermalScheme::kBackwardEuler, 2.0);
  const double cn = FirstModeError(ThermalScheme::kCrankNicolson, 4.0) /
                    FirstModeError(ThermalScheme::kCrankNicolson, 2.0);
  EXPECT_NEAR(be, 2.0, 0.15);
  EXPECT_NEAR(cn, 4.0, 0.3);
}

TEST(RadialConduction, BackwardEulerIsStableAndMonotoneForHugeSteps) {
  const ThermalParameters p = DirichletParams(ThermalScheme::kBackwardEuler);
  RadialConduction pack(0.046, 0.054, 32, p);  // cell time dr^2 / a = 0.42 s
  pack.SetUniform(1.0);
  double previous_mid = 1.0;
  for (int s = 0; s < 20; ++s) {
    pack.Step(1000.0, 0.0, 0.0, 0.0, 0.0);
    for (int i = 0; i < pack.cells(); ++i) {
      ASSERT_GE(pack.temperature_c()[i], 0.0);
      ASSERT_LE(pack.temperature_c()[i], 1.0);
    }
    const double mid = pack.temperature_c()[16];
    EXPECT_LE(mid, previous_mid);
    previous_mid = mid;
  }
  EXPECT_LT(pack.temperature_c().cwiseAbs().maxCoeff(), 1e-6);
}

TEST(RadialConduction, CrankNicolsonStaysBoundedButRingsForHugeSteps) {
  const ThermalParameters p = DirichletParams(ThermalScheme::kCrankNicolson);
  RadialConduction pack(0.046, 0.054, 32, p);
  pack.SetUniform(1.0);
  bool sign_change = false;
  double previous_edge = 1.0;
  for (int s = 0; s < 20; ++s) {
    pack.Step(1000.0, 0.0, 0.0, 0.0, 0.0);
    ASSERT_LE(pack.temperature_c().cwiseAbs().maxCoeff(), 1.0 + 1e-12);
    const double edge = pack.temperature_c()[0];
    sign_change |= edge * previous_edge < 0.0;
    previous_edge = edge;
  }
  EXPECT_TRUE(sign_change);  // why backward Euler is the default
}

TEST(RadialConduction, ThinConductivePackIsALumpedFirstOrderLag) {
  ThermalParameters p;
  p.conductivity_w_mk = 50.0;  // Biot number h w / k ~ 1e-3
  p.diffusivity_m2_s = 1e-5;
  const double r1 = 0.046, r2 = 0.054;
  RadialConduction pack(r1, r2, 32, p);
  const double rho_c = p.conductivity_w_mk / p.diffusivity_m2_s;
  const double tau = rho_c * 0.5 * (r2 * r2 - r1 * r1) /
                     (p.inner_conductance_w_m2k * r1 + p.outer_conductance_w_m2k * r2);
  EXPECT_NEAR(pack.RampLagSeconds(), tau, 0.005 * tau);
  pack.SetUniform(0.0);
  double t = 0.0;
  for (int s = 0; s < 2000; ++s, t += 1.0) pack.Step(1.0, 1.0, 1.0, 1.0, 1.0);
  EXPECT_NEAR(pack.MeanTemperature(), 1.0 - std::exp(-t / tau), 0.005);
}

TEST(RadialConduction, RampLagMatchesTheSteppedRampResponse) {
  ThermalParameters p;  // navigation pack
  RadialConduction pack(0.046, 0.054, 32, p);
  pack.SetUniform(0.0);
  const double slope = 1.0 / 60.0, h = 0.5;
  double t = 0.0;
  for (int s = 0; s < 4 * 3600 * 2; ++s) {
    pack.Step(h, slope * t, slope * (t + h), slope * t, slope * (t + h));
    t += h;
  }
  const double measured_lag = (slope * t - pack.MeanTemperature()) / slope;
  EXPECT_NEAR(measured_lag, pack.RampLagSeconds(), 0.005 * pack.RampLagSeconds());
  EXPECT_GT(pack.RampLagSeconds(), 5 * 60.0);   // minutes ...
  EXPECT_LT(pack.RampLagSeconds(), 60 * 60.0);  // ... not hours
}

TEST(RadialConduction, RejectsBadGeometryAndParameters) {
  ThermalParameters p;
  EXPECT_THROW(RadialConduction(0.05, 0.04, 10, p), UsageError);
  EXPECT_THROW(RadialConduction(0.04, 0.05, 0, p), UsageError);
  p.diffusivity_m2_s = 1.0;
  EXPECT_THROW(RadialConduction(0.04, 0.05, 10, p), UsageError);
  EXPECT_THROW(ThermalSchemeFromString("euler"), UsageError);
  EXPECT_EQ(ThermalSchemeFromString(ToString(ThermalScheme::kCrankNicolson)),
            ThermalScheme::kCrankNicolson);
}

}  // namespace
}  // namespace gyrodrift::simulation
