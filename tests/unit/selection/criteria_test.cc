// The selection criteria on hand-made curves (pdf_similarity.cc and criteria.cc): k* on ties, the
// pdf criterion's noise run against a supplied white-noise level, the two-group rules, and the
// energy curve's band exit. selection_test runs them through SelectModes on decomposed signals.
#include "selection/criteria.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::selection::internal {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// A result holding the curves the boundary rules read.
SelectionResult Curves(std::vector<double> self_distance, int k_star) {
  SelectionResult r;
  r.num_imfs = static_cast<int>(self_distance.size());
  r.self_distance = std::move(self_distance);
  r.k_star = k_star;
  return r;
}

// Options with a supplied level for 100-sample records (30 realisations, seed 7) that is the same
// for every family of modes tested together (no spread: the family level is the median).
SelectionOptions WithLevel(std::vector<double> level) {
  auto supplied = std::make_shared<NoiseLevel>();
  supplied->length = 100;
  supplied->realisations = 30;
  supplied->seed = 7;
  supplied->mad.assign(level.size(), 0.0);
  supplied->family_scale.assign(level.size(), 0.0);
  supplied->median = level;
  supplied->level = std::move(level);
  SelectionOptions o;
  o.noise_level = supplied;
  return o;
}

TEST(Criteria, KStarIsTheFirstMaximumOfTheDistance) {
  EXPECT_EQ(KStar({0.3}), 1);
  EXPECT_EQ(KStar({0.1, 0.5, 0.2, 0.5}), 2);
  EXPECT_EQ(KStar({0.1, 0.2, 0.3}), 3);
}

// The noise run is the leading IMFs with G_k at or under the level: a later IMF under it does not
// rejoin, and a NaN level ends the run. mixed_end = k*: the run never passes k*.
// Modes 1..k* are tested together: each at median + c_{k*} MAD, the scale of the whole family, so
// a mode above the level it would have alone (c_1) still passes; past k* the curve shows each
// mode's level as the last of a family 1..k.
TEST(Criteria, PdfSimilarityJudgesModesOneToKStarAsOneFamily) {
  SelectionOptions o = WithLevel({0.1, 0.1, 0.1, 0.1, 0.1});
  auto level = std::make_shared<NoiseLevel>(*o.noise_level);
  level->mad = {0.01, 0.01, 0.01, 0.01, 0.01};
  level->family_scale = {2.0, 3.0, 4.0, 4.0, 5.0};
  o.noise_level = level;
  SelectionResult r = Curves({0.13, 0.135, 0.139, 0.2, 0.1}, 3);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 3);  // mode 1 alone would fail (0.13 > 0.1 + 2 x 0.01)
  ASSERT_EQ(r.noise_level.size(), 5u);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(r.noise_level[static_cast<size_t>(k)], 0.14) << k;
  EXPECT_DOUBLE_EQ(r.noise_level[3], 0.14);
  EXPECT_DOUBLE_EQ(r.noise_level[4], 0.15);
  EXPECT_EQ(r.note, "noise run reaches k*: no mixed group");
  // With k* = 1 the family is mode 1 alone: 0.13 is above its 0.12.
  r = Curves({0.13, 0.135, 0.139, 0.2, 0.1}, 1);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 0);
  EXPECT_DOUBLE_EQ(r.noise_level[0], 0.12);
}

TEST(Criteria, PdfSimilarityRunEndsAtTheFirstImfAboveTheLevel) {
  const SelectionOptions o = WithLevel({0.5, 0.5, 0.5, 0.5, 0.5});
  SelectionResult r = Curves({0.1, 0.5, 0.9, 0.1, 0.1}, 4);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 2);
  EXPECT_EQ(r.mixed_end, 4);
  EXPECT_EQ(r.noise_level, (std::vector<double>{0.5, 0.5, 0.5, 0.5, 0.5}));
  EXPECT_EQ(r.noise_level_realisations, 30);
  EXPECT_EQ(r.noise_level_seed, 7u);
  EXPECT_FALSE(r.noise_level_computed);
  EXPECT_EQ(r.note, "");

  // Modes after k* are not judged: mode 2 is under the level but stays with the drift.
  r = Curves({0.1, 0.5, 0.9, 0.1, 0.1}, 1);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 1);
  EXPECT_EQ(r.mixed_end, 1);
  EXPECT_EQ(r.note,
            "noise run reaches k*: no mixed group (mode 2 also passes the white-noise test, "
            "left to the drift group)");
  r = Curves({0.1, 0.5, 0.1, 0.1, 0.1}, 2);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 2);
  EXPECT_EQ(r.mixed_end, 2);
  EXPECT_EQ(r.note,
            "noise run reaches k*: no mixed group (modes 3..5 also pass the white-noise test, "
            "left to the drift group)");
  r = Curves({0.1, 0.9, 0.1, 0.1, 0.1}, 1);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 1);
  EXPECT_EQ(r.note, "noise run reaches k*: no mixed group");

  r = Curves({0.9, 0.1, 0.1, 0.1, 0.1}, 3);
  PdfSimilarityBoundaries(100, o, {}, &r);
  EXPECT_EQ(r.k_noise, 0);
  EXPECT_EQ(r.mixed_end, 3);
  EXPECT_EQ(r.note, "no IMF passes the white-noise test: no noise group");

  r = Curves({0.1, 0.1, 0.1, 0.1, 0.1}, 5);
  PdfSimilarityBoundaries(100, WithLevel({0.5, kNan, 0.5, 0.5, 0.5}), {}, &r);
  EXPECT_EQ(r.k_noise, 1);
}

TEST(Criteria, KomatyAndEnergyModelSplitInTwo) {
  SelectionResult r = Curves({0.1, 0.1, 0.1, 0.1}, 3);
  r.energy_signal_start = 2;
  KomatyBoundaries(&r);
  EXPECT_EQ(r.k_noise, 3);
  EXPECT_EQ(r.mixed_end, 3);
  EnergyModelBoundaries(&r);
  EXPECT_EQ(r.k_noise, 1);
  EXPECT_EQ(r.mixed_end, 1);
  r.energy_signal_start = 5;  // every mode inside the band: all noise, the drift is the residue
  EnergyModelBoundaries(&r);
  EXPECT_EQ(r.k_noise, 4);
  EXPECT_EQ(r.mixed_end, 4);
}

// The curve is log2 of each IMF's energy beside the band's limit (energy_band.h, at the given
// confidence); the exit is the first mode k >= 2 above it. A zero mode 1 has no noise energy to
// scale the band by: every later mode is outside.
TEST(Criteria, EnergyCurveExitsAtTheFirstModeAboveTheBand) {
  const int n = 64;
  Eigen::MatrixXd imfs(n, 4);
  for (int t = 0; t < n; ++t) imfs(t, 0) = t % 2 ? 1.0 : -1.0;
  for (double confidence : {0.99, 0.95}) {
    decomposition::EnergyBand band;
    band.confidence = confidence;
    band.log2_e1 = decomposition::RobustLog2NoiseEnergy(imfs.col(0));
    // Modes 2 and 4 a factor 2 under the band's limit, mode 3 a factor 2 over it.
    for (int k = 2; k <= 4; ++k) {
      const double log2_energy = band.Log2Upper(k) + (k == 3 ? 1.0 : -1.0);
      imfs.col(k - 1).setConstant(std::sqrt(std::exp2(log2_energy) / n));
    }
    SelectionResult r;
    EnergyCurve(imfs, confidence, &r);
    ASSERT_EQ(r.log2_energy.size(), 4u);
    ASSERT_EQ(r.energy_band_log2_upper.size(), 4u);
    EXPECT_TRUE(std::isnan(r.energy_band_log2_upper[0]));
    for (int k = 1; k <= 4; ++k) {
      EXPECT_EQ(r.log2_energy[k - 1], std::log2(imfs.col(k - 1).squaredNorm())) << k;
      if (k >= 2) {
        EXPECT_EQ(r.energy_band_log2_upper[k - 1], band.Log2Upper(k)) << k;
      }
    }
    EXPECT_EQ(r.energy_signal_start, 3) << confidence;
  }
  imfs.col(2) = imfs.col(3);  // every mode inside
  SelectionResult inside;
  EnergyCurve(imfs, 0.95, &inside);
  EXPECT_EQ(inside.energy_signal_start, 5);
  imfs.col(0).setZero();
  SelectionResult zero;
  EnergyCurve(imfs, 0.99, &zero);
  EXPECT_EQ(zero.energy_signal_start, 2);
}

}  // namespace
}  // namespace gyrodrift::selection::internal
