// Plain EMD (src/decomposition/emd.cc): emd.m's main loop, its stop rules and report, and the
// incremental noise EMD the CEEMDAN family builds on. What the whole family shares (completeness,
// thread independence, the tone split) is in tests/property/decomposition; the match with
// emd.m's numbers in tests/regression/decomposition.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "decomposition/drivers.h"
#include "decomposition/sifting.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition {
namespace {

Eigen::VectorXd WhiteNoise(Eigen::Index n, std::uint64_t stream) {
  Eigen::VectorXd w(n);
  Rng(31, stream).FillNormal(w);
  return w;
}

Eigen::VectorXd Noisy(Eigen::Index n) {
  Eigen::VectorXd x = 0.5 * WhiteNoise(n, 0);
  for (Eigen::Index i = 0; i < n; ++i) x[i] += std::sin(2 * std::numbers::pi * i / 64.0);
  return x;
}

// (-1)^i: every interior sample an extremum, constant envelopes +-1, a mean of exactly zero.
Eigen::VectorXd Alternating(Eigen::Index n) {
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = i % 2 ? -1.0 : 1.0;
  return x;
}

TEST(Emd, SampleStdIsMatlabsWithNMinusOne) {
  // {1, 2, 3, 4}: mean 2.5, squared deviations sum to 5, std = sqrt(5 / 3).
  const double x[] = {1, 2, 3, 4};
  EXPECT_DOUBLE_EQ(internal::SampleStd(x, 4), std::sqrt(5.0 / 3.0));
}

// A small oscillation on a large offset: once it is out, the residue is the offset's rounding, and
// EMD and ICEEMDAN added rounding IMFs without end (a hang with growing memory at 1e12 + sin).
// They stop, complete to the offset's rounding.
TEST(Emd, AResidueAtItsRoundingEndsTheDecomposition) {
  Eigen::VectorXd x(50);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = 1e12 + std::sin(static_cast<double>(i) / 3.0);
  for (const Method method : {Method::kEmd, Method::kIceemdan, Method::kBeemdan}) {
    DecompositionOptions o;
    o.method = method;
    o.ensemble_size = 10;
    const Decomposition d = Decompose(x, o);
    EXPECT_GE(d.imfs.cols(), 1) << ToString(method);
    EXPECT_LE(d.imfs.cols(), 8) << ToString(method);
    const Eigen::VectorXd sum = d.imfs.rowwise().sum() + d.residue;
    EXPECT_LE((sum - x).cwiseAbs().maxCoeff(), 1e-3) << ToString(method);  // ulp(1e12) = 1.2e-4
  }
  DecompositionOptions emd;
  emd.method = Method::kEmd;
  const std::string reason = Decompose(x, emd).report.stop_reason;
  EXPECT_TRUE(reason == "residue varies by no more than the rounding of its magnitude" ||
              reason == "the next IMF is below the rounding of the residue")
      << reason;
}

TEST(Emd, DrawsNoNoiseSoEnsembleFieldsDoNotMatter) {
  const Eigen::VectorXd x = Noisy(1000);
  DecompositionOptions o;
  o.method = Method::kEmd;
  const Decomposition a = Decompose(x, o);
  o.seed = 12345;
  o.ensemble_size = 3;
  o.noise_strength = 5.0;
  o.beemdan_bound = BeemdanBound::kFull;
  const Decomposition b = Decompose(x, o);
  EXPECT_EQ(a.imfs, b.imfs);
  EXPECT_EQ(a.residue, b.residue);
  EXPECT_EQ(a.report.ensemble_size, 0);
  EXPECT_EQ(a.report.noise_assisted_stages, 0);
  EXPECT_FALSE(a.report.supplied_noise);
  // The convenience entry point is the same decomposition.
  const Decomposition c = Emd(x);
  EXPECT_EQ(a.imfs, c.imfs);
  EXPECT_EQ(a.report.sifts_per_imf, c.report.sifts_per_imf);
}

// EMD is defined recursively: IMF k is the first IMF of the residue left by IMFs 1..k-1, and the
// residue is what remains after subtracting them one by one (which makes the sum exact).
TEST(Emd, EachImfIsTheFirstImfOfThePreviousResidue) {
  const Eigen::VectorXd x = Noisy(1024);
  const Decomposition d = Emd(x);
  ASSERT_GE(d.num_imfs(), 4) << d.report.Summary();
  Eigen::VectorXd r = x;
  for (int k = 0; k < d.num_imfs(); ++k) {
    const Decomposition first = Emd(r, {}, 1);
    ASSERT_EQ(first.num_imfs(), 1) << k;
    EXPECT_EQ(Eigen::VectorXd(d.imfs.col(k)), Eigen::VectorXd(first.imfs.col(0))) << "IMF " << k;
    EXPECT_EQ(first.report.sifts_per_imf[0], d.report.sifts_per_imf[static_cast<size_t>(k)]);
    r -= d.imfs.col(k);
  }
  EXPECT_EQ(r, d.residue);
}

// Every IMF the Rilling rule accepted (not stopped by the cap) has zero crossings and extrema
// differing by at most one; the decomposition ends at a residue with fewer than 3 extrema.
TEST(Emd, ImfsSatisfyTheImfConditionAndTheResidueIsMonotoneEnough) {
  const Eigen::VectorXd x = Noisy(2048);
  const Decomposition d = Emd(x);
  ASSERT_EQ(d.report.sift_cap_hits, 0) << d.report.Summary();
  for (int k = 0; k < d.num_imfs(); ++k) {
    const Eigen::VectorXd imf = d.imfs.col(k);
    const internal::ExtremaCounts c = internal::CountExtrema(imf.data(), imf.size());
    EXPECT_LE(std::abs(c.extrema() - c.zero_crossings), 1) << "IMF " << k + 1;
    EXPECT_GE(c.extrema(), 3) << "IMF " << k + 1;
  }
  EXPECT_LT(internal::CountExtrema(d.residue.data(), d.residue.size()).extrema(), 3);
  EXPECT_EQ(d.report.stop_reason, "residue has fewer than 3 extrema");
}

// EMD of white noise is a dyadic filter bank (Flandrin, Rilling & Goncalves 2004): each IMF halves
// the mean frequency, so the IMF count is about log2 N and grows by one per doubling of N.
TEST(Emd, WhiteNoiseGivesAboutLog2NImfs) {
  const int realisations = 6;
  double mean_count[2] = {0, 0};
  const Eigen::Index lengths[2] = {256, 2048};  // log2: 8 and 11
  for (int l = 0; l < 2; ++l) {
    for (int r = 0; r < realisations; ++r) {
      const int k = Emd(WhiteNoise(lengths[l], 10 + r)).num_imfs();
      const double log2n = std::log2(static_cast<double>(lengths[l]));
      EXPECT_GE(k, log2n - 3) << lengths[l];
      EXPECT_LE(k, log2n + 1) << lengths[l];
      mean_count[l] += static_cast<double>(k) / realisations;
    }
  }
  EXPECT_NEAR(mean_count[1] - mean_count[0], 3.0, 1.0);  // 8x the samples: 3 more IMFs
}

// A signal that is already an IMF with constant envelopes has a mean of exactly zero: the Rilling
// rule accepts it before the first sift, and it is its own single IMF with nothing left.
TEST(Emd, AnImfWithZeroMeanIsItsOwnOnlyImfAfterNoSift) {
  const Eigen::VectorXd x = Alternating(101);
  const Decomposition d = Emd(x);
  ASSERT_EQ(d.num_imfs(), 1) << d.report.Summary();
  EXPECT_EQ(Eigen::VectorXd(d.imfs.col(0)), x);
  EXPECT_EQ(d.report.sifts_per_imf, std::vector<int>{0});
  EXPECT_TRUE(d.residue.isZero(0.0));
}

// emd.m also stops when the residue is negligible against the input: (-1)^i plus a slow wave of
// 1e-11 leaves, after the first IMF took the alternation, a residue of about 1e-11 with plenty
// of extrema, under 1e-10 of the input's amplitude.
TEST(Emd, StopsWhenTheResidueIsNegligible) {
  const Eigen::Index n = 512;
  Eigen::VectorXd x = Alternating(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] += 1e-11 * std::sin(2 * std::numbers::pi * i / 100.0);
  SiftingOptions fixed;
  fixed.stop_rule = StopRule::kFixed;  // sift the slow wave out of the first IMF
  const Decomposition d = Emd(x, fixed);
  ASSERT_EQ(d.num_imfs(), 1) << d.report.Summary();
  EXPECT_GE(internal::CountExtrema(d.residue.data(), n).extrema(), 3);
  EXPECT_LT(d.residue.cwiseAbs().maxCoeff(), 1e-10 * x.cwiseAbs().maxCoeff());
  EXPECT_EQ(d.report.stop_reason, "residue below 1e-10 of the input amplitude");
}

TEST(Emd, ImfCapEndsTheDecompositionAndSaysSo) {
  const Eigen::VectorXd x = Noisy(1024);
  const Decomposition all = Emd(x);
  const Decomposition capped = Emd(x, {}, 3);
  ASSERT_GT(all.num_imfs(), 3);
  ASSERT_EQ(capped.num_imfs(), 3);
  EXPECT_EQ(capped.imfs, all.imfs.leftCols(3));  // the cap truncates, it does not change modes
  EXPECT_EQ(capped.report.stop_reason, "IMF cap (3) reached");
  // What the cap left over is the rest of the full decomposition.
  const Eigen::VectorXd rest = all.imfs.rightCols(all.num_imfs() - 3).rowwise().sum() + all.residue;
  EXPECT_LE((capped.residue - rest).cwiseAbs().maxCoeff(), 1e-12 * x.cwiseAbs().maxCoeff());
}

TEST(Emd, SiftCapIsReportedPerImf) {
  const Eigen::VectorXd x = Noisy(1024);
  SiftingOptions one;
  one.max_sifts = 1;
  const Decomposition d = Emd(x, one);
  ASSERT_GE(d.num_imfs(), 2);
  int hits = 0;
  for (int k = 0; k < d.num_imfs(); ++k) {
    EXPECT_LE(d.report.sifts_per_imf[static_cast<size_t>(k)], 1) << k;
    // A cap hit means the cap's sift was made.
    if (d.report.sift_cap_hit[static_cast<size_t>(k)]) {
      EXPECT_EQ(d.report.sifts_per_imf[static_cast<size_t>(k)], 1) << k;
    }
    hits += d.report.sift_cap_hit[static_cast<size_t>(k)];
  }
  // Noise needs more than one sift per IMF under the Rilling rule: the cap must bite.
  EXPECT_GE(hits, 1);
  EXPECT_EQ(d.report.sift_cap_hits, hits);
  EXPECT_NE(d.report.Summary().find("sift cap hit " + std::to_string(hits) + " times"),
            std::string::npos)
      << d.report.Summary();
  // Without the cap, the same signal needs more sifts and never hits the default cap of 2000.
  const Decomposition free = Emd(x);
  EXPECT_EQ(free.report.sift_cap_hits, 0);
  EXPECT_GT(free.report.sifts_per_imf.front(), 1);
}

TEST(Emd, FixedRuleSiftsExactlyThatOftenAndIsNotACapHit) {
  const Eigen::VectorXd x = Noisy(1024);
  SiftingOptions fixed;
  fixed.stop_rule = StopRule::kFixed;
  fixed.fixed_sifts = 3;
  const Decomposition d = Emd(x, fixed);
  ASSERT_GE(d.num_imfs(), 3);
  // The last IMFs may run out of extrema mid-way (emd.m's catch); the first ones never do.
  for (int k = 0; k < 3; ++k) EXPECT_EQ(d.report.sifts_per_imf[static_cast<size_t>(k)], 3) << k;
  EXPECT_EQ(d.report.sift_cap_hits, 0);
  // A cap below the fixed count does bite.
  fixed.max_sifts = 2;
  const Decomposition capped = Emd(x, fixed);
  EXPECT_EQ(capped.report.sifts_per_imf.front(), 2);
  EXPECT_TRUE(capped.report.sift_cap_hit.front());
}

// The incremental noise EMD (NoiseModes) gives emd.m's rows: IMFs, then the residue unless it is
// identically zero.
TEST(Emd, NoiseModesListImfsThenANonZeroResidue) {
  const Eigen::Index n = 64;
  internal::Sifter sifter(n, SiftingOptions{});
  Eigen::VectorXd row(n);
  {
    // (-1)^i: one IMF, itself, and a zero residue that is left out.
    internal::NoiseModes modes(Alternating(n));
    ASSERT_TRUE(modes.Next(sifter, row.data()));
    EXPECT_EQ(modes.last_imf(), 1);
    EXPECT_EQ(row, Alternating(n));
    EXPECT_FALSE(modes.Next(sifter, row.data()));
  }
  {
    // Offset by 0.5: the first sift removes the constant mean exactly, leaving (-1)^i as the IMF
    // and the constant 0.5 as a residue row.
    internal::NoiseModes modes((Alternating(n).array() + 0.5).matrix());
    ASSERT_TRUE(modes.Next(sifter, row.data()));
    EXPECT_EQ(modes.last_imf(), 1);
    EXPECT_EQ(row, Alternating(n));
    ASSERT_TRUE(modes.Next(sifter, row.data()));
    EXPECT_EQ(modes.last_imf(), 0);
    EXPECT_TRUE((row.array() == 0.5).all());
    EXPECT_FALSE(modes.Next(sifter, row.data()));
  }
  {
    // White noise: the rows are Emd's IMFs and residue, one at a time.
    const Eigen::VectorXd w = WhiteNoise(n, 3);
    const Decomposition emd = Emd(w);
    internal::NoiseModes modes(w);
    for (int k = 0; k < emd.num_imfs(); ++k) {
      ASSERT_TRUE(modes.Next(sifter, row.data())) << k;
      EXPECT_EQ(modes.last_imf(), k + 1);
      EXPECT_EQ(row, Eigen::VectorXd(emd.imfs.col(k))) << k;
    }
    ASSERT_TRUE(modes.Next(sifter, row.data()));
    EXPECT_EQ(modes.last_imf(), 0);
    EXPECT_EQ(row, emd.residue);
    EXPECT_FALSE(modes.Next(sifter, row.data()));
  }
}

// Two tones an octave-and-more apart beyond the family's shared check: the first IMF is the fast
// tone itself away from the ends, where the mirrored boundary is only approximate.
TEST(Emd, FirstImfOfTwoSeparatedTonesIsTheFastTone) {
  const int n = 2048;
  Eigen::VectorXd fast(n), slow(n);
  for (int i = 0; i < n; ++i) {
    fast[i] = std::sin(2 * std::numbers::pi * i / 10.0);
    slow[i] = 2.0 * std::sin(2 * std::numbers::pi * i / 400.0);
  }
  const Decomposition d = Emd(fast + slow);
  ASSERT_GE(d.num_imfs(), 2);
  const Eigen::Index edge = 100;
  const Eigen::VectorXd error =
      d.imfs.col(0).segment(edge, n - 2 * edge) - fast.segment(edge, n - 2 * edge);
  // Leakage of the slow tone into IMF 1, against the fast tone's unit amplitude.
  EXPECT_LT(error.cwiseAbs().maxCoeff(), 1e-4);  // measured 3.4e-6
}

}  // namespace
}  // namespace gyrodrift::decomposition
