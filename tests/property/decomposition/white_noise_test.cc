// EMD of white Gaussian noise acts as a dyadic filter bank (Flandrin, Rilling & Goncalves 2004;
// Wu & Huang 2004): consecutive IMF energies fall by about 2. BEEMDAN compares each mode's energy
// with white noise's to keep noise assistance exactly while the modes are noise-dominated.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition {
namespace {

Eigen::VectorXd WhiteNoise(Eigen::Index n, std::uint64_t stream) {
  Eigen::VectorXd w(n);
  Rng rng(99, stream);
  rng.FillNormal(w);
  return w;
}

TEST(WhiteNoise, EnergyRatioOfConsecutiveImfsIsAboutTwo) {
  // Average log2 energy ratios of IMFs 2..6 over 20 realisations of 4096 samples.
  const int realisations = 20;
  std::vector<double> log_ratio(4, 0.0);
  for (int r = 0; r < realisations; ++r) {
    const Decomposition d = Emd(WhiteNoise(4096, static_cast<std::uint64_t>(r)));
    ASSERT_GE(d.num_imfs(), 6);
    for (int k = 1; k < 5; ++k) {
      log_ratio[static_cast<size_t>(k - 1)] +=
          std::log2(d.imfs.col(k).squaredNorm() / d.imfs.col(k + 1).squaredNorm()) / realisations;
    }
  }
  for (double lr : log_ratio) EXPECT_NEAR(std::exp2(lr), 2.0, 0.35);
}

TEST(WhiteNoise, BeemdanKeepsNoiseAssistanceThroughNoiseModes) {
  DecompositionOptions o;  // BEEMDAN defaults
  o.ensemble_size = 20;
  const Decomposition d = Decompose(WhiteNoise(4096, 100), o, {.execution = {.threads = 2}});
  // Pure noise: every tested mode stays in the 99 % band until the residue runs out of extrema
  // or only a few modes with too few samples per oscillation remain.
  EXPECT_GE(d.report.noise_assisted_stages, 6) << d.report.Summary();
}

// The sine (period 512 samples) sits near mode 8 of the dyadic bank; under both bands (the
// ensemble's, the default, and Flandrin et al.'s) noise assistance must end before it, and the
// plain-EMD mode that follows carries the sine.
TEST(WhiteNoise, BeemdanStopsAtASlowSinusoidsMode) {
  const int n = 4096;
  Eigen::VectorXd sine(n);
  for (int i = 0; i < n; ++i) sine[i] = 3.0 * std::sin(2 * std::numbers::pi * i / 512.0);
  const Eigen::VectorXd x = 0.2 * WhiteNoise(n, 101) + sine;
  for (const BeemdanBound bound : {BeemdanBound::kEnergyBand, BeemdanBound::kEnsembleBand}) {
    DecompositionOptions o;
    o.ensemble_size = 20;
    o.beemdan_bound = bound;
    const Decomposition d = Decompose(x, o, {.execution = {.threads = 2}});
    SCOPED_TRACE(d.report.Summary());
    const int stages = d.report.noise_assisted_stages;
    ASSERT_GT(stages, 0);
    EXPECT_LE(stages, 8);
    EXPECT_NE(d.report.stop_reason.find("white-noise band"), std::string::npos);
    double best = 0;
    int best_k = -1;
    for (int k = 0; k < d.num_imfs(); ++k) {
      const double c = d.imfs.col(k).dot(sine) / (d.imfs.col(k).norm() * sine.norm());
      if (c > best) {
        best = c;
        best_k = k;
      }
    }
    // 0-based: the first plain mode is column `stages`, the last noise-assisted one before it.
    EXPECT_GE(best_k, stages) << "the sine's mode was noise-assisted";
    EXPECT_GT(best, 0.95);
  }
}

TEST(Beemdan, FixedStageBoundAndFullDepth) {
  const Eigen::VectorXd x = WhiteNoise(1024, 102);
  DecompositionOptions o;
  o.ensemble_size = 8;
  o.beemdan_bound = BeemdanBound::kFixedStages;
  o.noise_stages = 2;
  const Decomposition d = Decompose(x, o);
  EXPECT_EQ(d.report.noise_assisted_stages, 2);
  EXPECT_LE((d.imfs.rowwise().sum() + d.residue - x).cwiseAbs().maxCoeff(), 1e-12 * x.cwiseAbs().maxCoeff());
  o.beemdan_bound = BeemdanBound::kFull;
  DecompositionOptions ice = o;
  ice.method = Method::kIceemdan;
  const Decomposition full = Decompose(x, o);
  const Decomposition reference = Decompose(x, ice);
  EXPECT_EQ(full.imfs, reference.imfs);
  EXPECT_EQ(full.residue, reference.residue);
}

}  // namespace
}  // namespace gyrodrift::decomposition
