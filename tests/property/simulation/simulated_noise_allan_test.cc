// A noise-only simulation, analysed with the allan module, gives back the Allan terms it was
// built from: the end-to-end check that the simulator's noise means what its parameters say.
#include <gtest/gtest.h>

#include <cmath>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/simulation/fog_simulator.h"

namespace gyrodrift::simulation {
namespace {

struct Recovery {
  allan::AllanResult curve;
  allan::NoiseTerms terms;
  NoiseParameters truth;
};

// 1e6 s (11.6 days) at 1 Hz in a chamber held at the bias reference temperature, so the drift
// is exactly zero and rate_dph is pure noise. N and Q are METHOD.md's; B and K are raised from the
// navigation defaults so that each term owns more than a decade of the curve in this record
// (ARW until ~70 s, the B floor to ~1e4 s, K beyond).
Recovery SimulateAndFit(std::uint64_t seed) {
  FogParameters p;
  p.noise.bias_instability_dph = 0.05;
  p.noise.rrw_dphpsh = 0.035;
  const auto flat = TemperatureProgramme::FromSegments(
      p.bias.reference_c, {{ProgrammeSegment::Kind::kDwell, 1e6, 0.0}});
  SimulationOptions o;
  o.duration_s = 1e6;
  o.seed = seed;
  const SimulationResult r = Simulate(flat, p, o);
  EXPECT_EQ(r.drift_dph.cwiseAbs().maxCoeff(), 0.0);
  allan::AllanOptions ao;
  ao.rate_hz = 1.0;
  ao.grid = allan::TauGrid::kOctave;
  ao.confidence = 0.95;
  Recovery rec{allan::Compute(r.rate_dph, ao), {}, p.noise};
  rec.terms = allan::IdentifyNoise(rec.curve);
  return rec;
}

class SimulatedNoiseAllan : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(SimulatedNoiseAllan, CurveAndFittedTermsMatchTheGeneratingParameters) {
  const Recovery rec = SimulateAndFit(GetParam());
  // 1. The exact Allan deviation of what was generated lies inside the 95 % confidence interval
  //    of (nearly) every estimated point. Neighbouring octave points are correlated, so allow a
  //    few misses.
  int covered = 0;
  for (const auto& point : rec.curve.points) {
    const double model = std::sqrt(NoiseAllanVariance(rec.truth, 1.0, point.m));
    covered += model >= point.dev_lo && model <= point.dev_hi;
  }
  const int points = static_cast<int>(rec.curve.points.size());
  EXPECT_GE(points, 18);
  EXPECT_GE(covered, points - 3) << rec.curve.Summary();

  // 2. The IEEE 952 fit finds N, B and K. Tolerances: the fit's own 1-sigma values (about 0.2 %,
  //    0.6 % and 5-10 % here) assume independent points, while overlapping estimates at
  //    neighbouring taus are correlated; over 8 seeds the generator matched its exact curve to
  //    0.2 % (ratio of mean AVAR) while the fitted N, B and K scattered by up to 0.5 %, 1.4 % and
  //    30 %, i.e. up to 4.5 reported sigmas. The bounds below are those of that spread.
  const allan::NoiseTerms& t = rec.terms;
  ASSERT_TRUE(t.n_dpsh.identified) << t.Summary();
  ASSERT_TRUE(t.b_dph.identified) << t.Summary();
  ASSERT_TRUE(t.k_dphpsh.identified) << t.Summary();
  EXPECT_NEAR(t.n_dpsh.value / rec.truth.arw_dpsh, 1.0, 0.01) << t.Summary();
  EXPECT_NEAR(t.b_dph.value / rec.truth.bias_instability_dph, 1.0, 0.03) << t.Summary();
  EXPECT_NEAR(t.k_dphpsh.value / rec.truth.rrw_dphpsh, 1.0, 0.35) << t.Summary();
  EXPECT_LT(std::abs(t.n_dpsh.value - rec.truth.arw_dpsh), 5 * t.n_dpsh.sigma) << t.Summary();
  EXPECT_LT(std::abs(t.b_dph.value - rec.truth.bias_instability_dph), 5 * t.b_dph.sigma)
      << t.Summary();
  EXPECT_LT(std::abs(t.k_dphpsh.value - rec.truth.rrw_dphpsh), 5 * t.k_dphpsh.sigma) << t.Summary();
}

INSTANTIATE_TEST_SUITE_P(Seeds, SimulatedNoiseAllan, ::testing::Values(1u, 2u, 3u));

}  // namespace
}  // namespace gyrodrift::simulation
