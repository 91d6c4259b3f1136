// The white-noise energy band (Flandrin, Goncalves & Rilling 2004) shared by BEEMDAN and the
// selection: its formula, its robust mode-1 energy, and that EMD modes of white noise fall
// inside it as often as its confidence says.
#include "gyrodrift/decomposition/energy_band.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition {
namespace {

TEST(EnergyBand, OnlyTheTwoFittedConfidencesAreAccepted) {
  EXPECT_NO_THROW(ValidateBandConfidence(0.95));
  EXPECT_NO_THROW(ValidateBandConfidence(0.99));
  for (double bad : {0.9, 0.98999, 1.0, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      ValidateBandConfidence(bad, "selection.band_confidence");
      ADD_FAILURE() << bad;
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("selection.band_confidence"), std::string::npos);
    }
  }
}

TEST(EnergyBand, UpperLimitIsTheWhiteNoiseModelPlusTheFittedSpread) {
  EnergyBand band;
  band.log2_e1 = 10.0;
  // E_k = E_1 / 0.719 * 2.01^-k, spread 2^(0.46 k - 1.919) at 99 %, 2^(0.474 k - 2.449) at 95 %.
  EXPECT_DOUBLE_EQ(band.Log2Upper(3),
                   10.0 - std::log2(0.719) - 3 * std::log2(2.01) + std::exp2(0.46 * 3 - 1.919));
  band.confidence = 0.95;
  EXPECT_DOUBLE_EQ(band.Log2Upper(3),
                   10.0 - std::log2(0.719) - 3 * std::log2(2.01) + std::exp2(0.474 * 3 - 2.449));
  EXPECT_TRUE(band.Contains(3, band.Log2Upper(3)));
  EXPECT_FALSE(band.Contains(3, std::nextafter(band.Log2Upper(3), 100.0)));
  EXPECT_FALSE(band.Contains(3, std::numeric_limits<double>::quiet_NaN()));
  band.log2_e1 = -std::numeric_limits<double>::infinity();  // a zero mode 1: nothing is noise
  EXPECT_FALSE(band.Contains(2, -1000.0));
}

TEST(EnergyBand, RobustModeOneEnergyIgnoresAFewLargeSamples) {
  Eigen::VectorXd mode(4);
  mode << 1.0, -2.0, 3.0, -4.0;  // median |d| = 2.5
  EXPECT_DOUBLE_EQ(RobustLog2NoiseEnergy(mode), 2.0 + 2.0 * std::log2(2.5 / 0.6745));
  Rng rng(3, 0);
  Eigen::VectorXd noise(4001);
  rng.FillNormal(noise);
  const double clean = RobustLog2NoiseEnergy(noise);
  EXPECT_NEAR(clean, std::log2(4001.0), 0.1);  // N sigma^2 for unit white noise
  noise.head(40).array() *= 100.0;              // 1 % of the samples become spikes
  EXPECT_NEAR(RobustLog2NoiseEnergy(noise), clean, 0.05);
}

// White noise decomposed by EMD: modes 2..6 lie inside the 99 % band almost always, and inside
// the narrower 95 % band less often.
TEST(EnergyBand, WhiteNoiseModesFallInsideTheBand) {
  int inside99 = 0, inside95 = 0, tested = 0;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    Eigen::VectorXd noise(4096);
    Rng rng(seed, 11);
    rng.FillNormal(noise);
    const Decomposition d = Emd(noise, SiftingOptions{}, 0);
    ASSERT_GE(d.num_imfs(), 6);
    EnergyBand band;
    band.log2_e1 = RobustLog2NoiseEnergy(d.imfs.col(0));
    EnergyBand narrow = band;
    narrow.confidence = 0.95;
    for (int k = 2; k <= 6; ++k) {
      const double log2_energy = std::log2(d.imfs.col(k - 1).squaredNorm());
      inside99 += band.Contains(k, log2_energy);
      inside95 += narrow.Contains(k, log2_energy);
      ++tested;
    }
  }
  EXPECT_GE(inside99, 0.95 * tested) << inside99 << " of " << tested;
  EXPECT_GE(inside95, 0.85 * tested) << inside95 << " of " << tested;
  EXPECT_LE(inside95, inside99);
}

}  // namespace
}  // namespace gyrodrift::decomposition
