// A noise-only simulation, analysed with the allan module, gives back the Allan terms it was
// built from: the end-to-end check that the simulator's noise means what its parameters say.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
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

  // 2. The IEEE 952 fit finds N, B and K within 3 of their reported standard uncertainties
  //    (the calibration of those uncertainties is the next test's job).
  const allan::NoiseTerms& t = rec.terms;
  ASSERT_TRUE(t.n_dpsh.identified) << t.Summary();
  ASSERT_TRUE(t.b_dph.identified) << t.Summary();
  ASSERT_TRUE(t.k_dphpsh.identified) << t.Summary();
  EXPECT_NEAR(t.n_dpsh.value / rec.truth.arw_dpsh, 1.0, 0.01) << t.Summary();
  EXPECT_NEAR(t.b_dph.value / rec.truth.bias_instability_dph, 1.0, 0.03) << t.Summary();
  EXPECT_NEAR(t.k_dphpsh.value / rec.truth.rrw_dphpsh, 1.0, 0.35) << t.Summary();
  EXPECT_LT(std::abs(t.n_dpsh.value - rec.truth.arw_dpsh), 3 * t.n_dpsh.sigma) << t.Summary();
  EXPECT_LT(std::abs(t.b_dph.value - rec.truth.bias_instability_dph), 3 * t.b_dph.sigma)
      << t.Summary();
  EXPECT_LT(std::abs(t.k_dphpsh.value - rec.truth.rrw_dphpsh), 3 * t.k_dphpsh.sigma) << t.Summary();
}

INSTANTIATE_TEST_SUITE_P(Seeds, SimulatedNoiseAllan, ::testing::Values(1u, 2u, 3u));

// The reported uncertainties are honest: over many independent records, (fit - target) / sigma
// has a root mean square near 1 and the 95 % intervals cover the target about 95 % of the time.
// The target is what the fit finds on the exact Allan curve of the generator (its projection on
// the five-term model): the bias bank's floor ripples by a few per cent, which no five-term model
// follows, and that model error is not the estimator's. The projection itself stays within a few
// per cent of the generating parameters. 40 records of 2e5 s at 1 Hz with ARW up to ~30 s, the
// bias floor to ~3000 s and rate random walk beyond; with calibrated uncertainties the RMS over
// 40 records is 1 +- 0.11, and the coverage 38 +- 1.4 of 40.
TEST(SimulatedNoiseAllanCalibration, UncertaintiesCoverTheTruthAtTheirStatedRate) {
  NoiseParameters p;
  p.bias_instability_dph = 0.075;
  p.rrw_dphpsh = 0.1;
  constexpr Eigen::Index kSamples = 200000;
  constexpr int kRecords = 40;
  allan::AllanOptions ao{.grid = allan::TauGrid::kOctave};
  // Projection of the exact curve (unbounded degrees of freedom: no estimation noise).
  const allan::AllanResult shape = allan::Compute(GenerateNoise(p, 1.0, kSamples, 0), ao);
  const auto points = static_cast<Eigen::Index>(shape.points.size());
  Eigen::VectorXd tau(points), exact(points), edf = Eigen::VectorXd::Constant(points, 1e12);
  for (Eigen::Index i = 0; i < points; ++i) {
    const auto& point = shape.points[static_cast<size_t>(i)];
    tau[i] = point.tau_s;
    exact[i] = std::sqrt(NoiseAllanVariance(p, 1.0, point.m));
  }
  const allan::NoiseTerms target = allan::IdentifyNoise(tau, exact, edf, {.sample_period_s = 1.0});
  EXPECT_NEAR(target.n_dpsh.value / p.arw_dpsh, 1.0, 0.01) << target.Summary();
  EXPECT_NEAR(target.b_dph.value / p.bias_instability_dph, 1.0, 0.03) << target.Summary();
  EXPECT_NEAR(target.k_dphpsh.value / p.rrw_dphpsh, 1.0, 0.05) << target.Summary();

  std::array<double, 3> sum_z2{}, covered{};
  int ramps = 0;
  for (int record = 1; record <= kRecords; ++record) {
    const allan::NoiseTerms t = allan::IdentifyNoise(
        allan::Compute(GenerateNoise(p, 1.0, kSamples, static_cast<std::uint64_t>(record)), ao));
    ramps += t.r_dphph.identified;
    const std::array<const allan::NoiseTerm*, 3> fitted{&t.n_dpsh, &t.b_dph, &t.k_dphpsh};
    const std::array<double, 3> truth{target.n_dpsh.value, target.b_dph.value,
                                      target.k_dphpsh.value};
    for (size_t j = 0; j < 3; ++j) {
      ASSERT_TRUE(fitted[j]->identified) << record << ": " << t.Summary();
      const double z = (fitted[j]->value - truth[j]) / fitted[j]->sigma;
      sum_z2[j] += z * z;
      covered[j] += std::abs(z) <= 1.96;
    }
  }
  const char* names[] = {"N", "B", "K"};
  for (size_t j = 0; j < 3; ++j) {
    const double rms = std::sqrt(sum_z2[j] / kRecords);
    std::printf("%s: rms z %.2f, 95 %% coverage %g of %d\n", names[j], rms, covered[j], kRecords);
    EXPECT_GT(rms, 0.6) << names[j];
    EXPECT_LT(rms, 1.4) << names[j];
    EXPECT_GE(covered[j], 34) << names[j];
  }
  // No rate ramp was generated: the nested test at 5 % keeps a term that is truly absent in about
  // 2.5 % of records (its null law is half chi-square 0, half chi-square 1). The rule it replaced
  // reported a ramp in 7 of these 40 records.
  std::printf("R reported in %d of %d records\n", ramps, kRecords);
  EXPECT_LE(ramps, 3);
}

// The main use case: an 8-hour thermal-chamber run of a navigation FOG (the simulator's defaults,
// METHOD.md section 1: B = 0.01 deg/h, K = 0.002 deg/h/sqrt(h), whose K^2 tau / 3 stays below a
// tenth of the floor up to 8192 s). The last octaves of such a curve carry 2-15 degrees of freedom,
// and over them a rising rate random walk can explain the excess over the white rate noise about
// as well as the flat floor. The fit must read the floor as bias instability: report B, with
// honest uncertainties, and not claim a K the record cannot show.
TEST(SimulatedNoiseAllanEightHours, ReadsTheFloorAsBiasInstabilityAndClaimsNoRateRandomWalk) {
  const NoiseParameters p;
  constexpr Eigen::Index kSamples = 28800;
  constexpr int kRecords = 40;
  const allan::AllanOptions ao{.grid = allan::TauGrid::kOctave};
  // What the five-term model can recover from the exact curve: B within 3 % of the setting, K
  // not identified (it never carries a tenth of the model in 8 hours).
  const allan::AllanResult shape = allan::Compute(GenerateNoise(p, 1.0, kSamples, 0), ao);
  const auto points = static_cast<Eigen::Index>(shape.points.size());
  Eigen::VectorXd tau(points), exact(points), edf = Eigen::VectorXd::Constant(points, 1e12);
  for (Eigen::Index i = 0; i < points; ++i) {
    tau[i] = shape.points[static_cast<size_t>(i)].tau_s;
    exact[i] = std::sqrt(NoiseAllanVariance(p, 1.0, shape.points[static_cast<size_t>(i)].m));
  }
  const allan::NoiseTerms target = allan::IdentifyNoise(tau, exact, edf, {.sample_period_s = 1.0});
  ASSERT_TRUE(target.b_dph.identified) << target.Summary();
  EXPECT_NEAR(target.b_dph.value / p.bias_instability_dph, 1.0, 0.03) << target.Summary();
  EXPECT_FALSE(target.k_dphpsh.identified) << target.Summary();

  // The record of the bug report: `gyrodrift simulate --profile chamber-b --seed 2`, column
  // noise_dph (the noise does not depend on the programme). Its curve is flat at 0.010-0.013
  // deg/h from 512 to 8192 s; the fit used to report B not identified and K = 0.021 +- 0.0057.
  {
    const allan::NoiseTerms t =
        allan::IdentifyNoise(allan::Compute(GenerateNoise(p, 1.0, kSamples, 2), ao));
    EXPECT_TRUE(t.b_dph.identified) << t.Summary();
    EXPECT_LT(std::abs(t.b_dph.value - p.bias_instability_dph), t.b_dph.sigma) << t.Summary();
    EXPECT_FALSE(t.k_dphpsh.identified) << t.Summary();
    EXPECT_FALSE(t.r_dphph.identified) << t.Summary();
  }

  // Over 40 records: B found in most (in the others the last octaves came out low and no floor is
  // significant), covering the target at the stated rate; K and R reported in at most a few. The
  // rule this replaced: B in 28, K in 16 (median 0.014; 7 of the 16 95 % intervals excluded the
  // setting), R in 4.
  int b_found = 0, b_covered = 0, k_found = 0, r_found = 0;
  double sum_z2 = 0.0;
  for (int record = 1; record <= kRecords; ++record) {
    const allan::NoiseTerms t = allan::IdentifyNoise(
        allan::Compute(GenerateNoise(p, 1.0, kSamples, static_cast<std::uint64_t>(record)), ao));
    k_found += t.k_dphpsh.identified;
    r_found += t.r_dphph.identified;
    if (t.k_dphpsh.identified) {  // a K the data show must not exclude the setting at 3 sigma
      EXPECT_LT(t.k_dphpsh.value - p.rrw_dphpsh, 3.0 * t.k_dphpsh.sigma)
          << record << ": " << t.Summary();
    }
    if (!t.b_dph.identified) continue;
    ++b_found;
    const double z = (t.b_dph.value - target.b_dph.value) / t.b_dph.sigma;
    sum_z2 += z * z;
    b_covered += std::abs(z) <= 1.96;
  }
  const double rms = std::sqrt(sum_z2 / std::max(1, b_found));
  std::printf("8 h: B found in %d of %d (rms z %.2f, 95 %% coverage %d), K in %d, R in %d\n",
              b_found, kRecords, rms, b_covered, k_found, r_found);
  EXPECT_GE(b_found, 28);
  EXPECT_GE(b_covered, b_found * 9 / 10);
  EXPECT_LT(rms, 1.4);
  EXPECT_LE(k_found, 2);
  EXPECT_LE(r_found, 2);
}

}  // namespace
}  // namespace gyrodrift::simulation
