// Properties every preset, winding and chamber programme must have.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "gyrodrift/simulation/fog_simulator.h"

namespace gyrodrift::simulation {
namespace {

double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / v.size()); }

using Case = std::tuple<Preset, std::string>;

class SimulatorProperties : public ::testing::TestWithParam<Case> {
 protected:
  SimulationResult Run(WindingPattern pattern, bool noise = false, double extra_s = 0.0) const {
    FogParameters p = PresetParameters(std::get<0>(GetParam()));
    p.coil.winding = pattern;
    SimulationOptions o;
    o.include_noise = noise;
    o.duration_s += extra_s;  // the programme holds its last temperature
    return Simulate(BuiltinProgramme(std::get<1>(GetParam())), p, o);
  }
};

// The Shupe term is a weighted sum of layer rates, so its time integral (an angle) is
// sum_l w_l (T_l(end) - T_l(0)); with sum_l w_l = 0 it vanishes once the pack is uniform again.
// The case and the navigation pack have nearly equal time constants (1200 s, 1227 s), so the
// gradient decays like t exp(-t / 20 min): 2 % is left after the 110-min final dwell of
// "chamber". Six more hours of dwell leave about 1e-8.
TEST_P(SimulatorProperties, ShupeAngleClosesAfterALongFinalDwell) {
  for (const auto pattern :
       {WindingPattern::kQuadrupole, WindingPattern::kDipole, WindingPattern::kConventional}) {
    const SimulationResult r = Run(pattern, false, 6 * 3600.0);
    double angle = 0.0, max_angle = 0.0;
    for (Eigen::Index k = 0; k < r.samples; ++k) {
      angle += r.shupe_dph[k];  // deg/h * s at 1 Hz
      max_angle = std::max(max_angle, std::abs(angle));
    }
    EXPECT_GT(max_angle, 0.0);
    EXPECT_LT(std::abs(angle), 1e-5 * max_angle) << ToString(pattern);
  }
}

TEST_P(SimulatorProperties, WindingSymmetryOrdersTheShupeResidue) {
  const double conventional = Rms(Run(WindingPattern::kConventional).shupe_dph);
  const double dipole = Rms(Run(WindingPattern::kDipole).shupe_dph);
  const double quadrupole = Rms(Run(WindingPattern::kQuadrupole).shupe_dph);
  const double octupole = Rms(Run(WindingPattern::kOctupole).shupe_dph);
  EXPECT_GT(conventional, 5 * dipole);
  EXPECT_GT(dipole, 3 * quadrupole);
  EXPECT_GT(quadrupole, 3 * octupole);
  EXPECT_LT(Run(WindingPattern::kSymmetric).shupe_dph.cwiseAbs().maxCoeff(), 1e-12);
}

TEST_P(SimulatorProperties, TruthAddsUpAndFollowsTheTemperatures) {
  const FogParameters p = PresetParameters(std::get<0>(GetParam()));
  const SimulationResult r = Run(p.coil.winding, /*noise=*/true);
  EXPECT_EQ(r.drift_dph, r.shupe_dph + r.stress_dph + r.bias_dph);
  EXPECT_EQ(r.rate_dph, r.drift_dph + r.noise_dph);
  for (Eigen::Index k = 0; k < r.samples; k += 997) {
    EXPECT_NEAR(r.stress_dph[k],
                r.stress_coefficient_dph_per_k * (r.coil_mean_c[k] - p.stress.reference_c), 1e-12);
    EXPECT_DOUBLE_EQ(r.bias_dph[k], p.bias.At(r.case_c[k]));
    // The coil mean stays inside the range the case has visited.
    EXPECT_LE(r.coil_mean_c[k], r.case_c.head(k + 1).maxCoeff() + 1e-9);
    EXPECT_GE(r.coil_mean_c[k], r.case_c.head(k + 1).minCoeff() - 1e-9);
  }
  // The logged temperature is the case's, within sensor noise, lag and rounding.
  EXPECT_LT(Rms(r.temperature_c - r.case_c), 1.0);
}

INSTANTIATE_TEST_SUITE_P(
    PresetsAndProgrammes, SimulatorProperties,
    ::testing::Combine(::testing::Values(Preset::kNavigation, Preset::kTactical),
                       ::testing::Values(std::string("chamber"), std::string("chamber-b"))),
    [](const auto& info) {
      std::string name =
          std::string(ToString(std::get<0>(info.param))) + "_" + std::get<1>(info.param);
      for (char& c : name) c = c == '-' ? '_' : c;
      return name;
    });

}  // namespace
}  // namespace gyrodrift::simulation
