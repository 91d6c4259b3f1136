// EEMD (src/decomposition/eemd.cc, Wu & Huang 2009): the mode-by-mode mean of the EMDs of
// x + eps std(x) w_i, every member held to one IMF count. The family's shared properties
// (the 1/sqrt(I) reconstruction error among them) are in tests/property/decomposition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "decomposition/drivers.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "unit/decomposition/hand_made.h"

namespace gyrodrift::decomposition {
namespace {

using hand_made::DrawnColumns;

Eigen::VectorXd Noisy(Eigen::Index n) {
  Eigen::VectorXd x(n);
  Rng rng(41, 0);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = 0.5 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 50.0) + 0.003 * i;
  }
  return x;
}

DecompositionOptions Eemd(int ensemble) {
  DecompositionOptions o;
  o.method = Method::kEemd;
  o.ensemble_size = ensemble;
  o.seed = 5;
  return o;
}

// d's modes as an N x k matrix, zero beyond the ones it has (as EEMD pads a short member).
Eigen::MatrixXd Padded(const Decomposition& d, int k) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(d.imfs.rows(), k);
  m.leftCols(d.num_imfs()) = d.imfs;
  return m;
}

// floor(log2 N) - 1 modes unless max_imfs says otherwise, so that every member lines up.
int DefaultImfCount(Eigen::Index n) {
  return static_cast<int>(std::floor(std::log2(static_cast<double>(n)))) - 1;
}

TEST(Eemd, ImfCountIsFixedByTheLengthOrTheCap) {
  for (const Eigen::Index n : {600, 1024}) {
    const Decomposition d = Decompose(Noisy(n), Eemd(4));
    EXPECT_EQ(d.num_imfs(), DefaultImfCount(n)) << n;  // 8 for 600 (log2 9.2), 9 for 1024
    EXPECT_EQ(d.report.sifts_per_imf.size(), static_cast<size_t>(d.num_imfs()));
    EXPECT_NE(d.report.stop_reason.find("fixed IMF count"), std::string::npos);
    EXPECT_EQ(d.report.noise_assisted_stages, 0);  // not a stage-wise method
  }
  // A cap above what the members can give still fixes the count: modes no member reached are 0.
  DecompositionOptions o = Eemd(4);
  o.max_imfs = 20;
  const Decomposition d = Decompose(Noisy(64), o);
  ASSERT_EQ(d.num_imfs(), 20);
  EXPECT_TRUE(d.imfs.col(19).isZero(0.0));
  EXPECT_FALSE(d.imfs.col(0).isZero(0.0));
}

// One member with zero supplied noise is the EMD of x itself, held to the EEMD mode count (modes
// past the member's last are zero).
TEST(Eemd, OneNoiseFreeMemberIsPlainEmd) {
  const Eigen::VectorXd x = Noisy(1024);
  const int k = DefaultImfCount(1024);
  const Decomposition eemd = DecomposeWithNoise(x, Eigen::MatrixXd::Zero(1024, 1), Eemd(1));
  const Decomposition emd = Emd(x, {}, k);
  ASSERT_EQ(eemd.num_imfs(), k);
  ASSERT_LE(emd.num_imfs(), k);
  EXPECT_EQ(eemd.imfs, Padded(emd, k));
  EXPECT_EQ(eemd.residue, emd.residue);
  for (int m = 0; m < emd.num_imfs(); ++m) {
    const size_t s = static_cast<size_t>(m);
    EXPECT_EQ(eemd.report.sifts_per_imf[s], emd.report.sifts_per_imf[s]) << m;
  }
  EXPECT_TRUE(eemd.report.supplied_noise);
}

// One drawn member is the EMD of x + eps std(x) w_0, w_0 from stream (seed, 0): the noise is
// relative to the signal's (sample) standard deviation.
TEST(Eemd, OneMemberIsTheEmdOfXPlusScaledNoise) {
  const Eigen::VectorXd x = Noisy(1024);
  DecompositionOptions o = Eemd(1);
  o.noise_strength = 0.3;
  Eigen::VectorXd w(1024);
  Rng(o.seed, 0).FillNormal(w);
  const double amplitude = o.noise_strength * internal::SampleStd(x.data(), x.size());
  const Eigen::VectorXd member = x + amplitude * w;
  const Decomposition emd = Emd(member, {}, DefaultImfCount(1024));
  const Decomposition eemd = Decompose(x, o);
  EXPECT_EQ(eemd.imfs, Padded(emd, DefaultImfCount(1024)));
  EXPECT_EQ(eemd.residue, emd.residue);
  EXPECT_EQ(eemd.report.ensemble_size, 1);
  EXPECT_EQ(eemd.report.seed, o.seed);
}

// The mean is taken mode by mode: with two members, each mode is the average of the members'.
TEST(Eemd, ModesAreTheMembersMeans) {
  const Eigen::VectorXd x = Noisy(512);
  const Eigen::MatrixXd w = DrawnColumns(77, 2, 512);
  const DecompositionOptions o = Eemd(2);
  const double amplitude = o.noise_strength * internal::SampleStd(x.data(), x.size());
  const int k = DefaultImfCount(512);
  const Decomposition a = Emd(x + amplitude * w.col(0), {}, k);
  const Decomposition b = Emd(x + amplitude * w.col(1), {}, k);
  const Decomposition d = DecomposeWithNoise(x, w, o);
  ASSERT_EQ(d.num_imfs(), k);
  const double scale = x.cwiseAbs().maxCoeff();
  EXPECT_LE((d.imfs - 0.5 * (Padded(a, k) + Padded(b, k))).cwiseAbs().maxCoeff(), 1e-14 * scale);
  EXPECT_LE((d.residue - 0.5 * (a.residue + b.residue)).cwiseAbs().maxCoeff(), 1e-14 * scale);
  // Sift counts are the means over the members that sifted the mode, rounded: a member that
  // ended before mode m is not a member that took 0 sifts for it.
  for (int m = 0; m < k; ++m) {
    const size_t s = static_cast<size_t>(m);
    double total = 0.0;
    int members = 0;
    for (const Decomposition* e : {&a, &b}) {
      if (m < e->num_imfs()) {
        total += e->report.sifts_per_imf[s];
        ++members;
      }
    }
    EXPECT_EQ(d.report.sifts_per_imf[s], members == 0 ? 0 : std::lround(total / members)) << m;
  }
}

// Modes only some members reach: their sift count is those members' mean (regression: the mean
// was over the whole ensemble, so a mode one member in four reached showed a quarter of its sifts).
TEST(Eemd, SiftCountsOfModesSomeMembersMissAreTheirSiftersMean) {
  const Eigen::VectorXd x = Noisy(64);
  DecompositionOptions o = Eemd(4);
  o.max_imfs = 8;
  const Eigen::MatrixXd w = DrawnColumns(79, 4, 64);
  const double amplitude = o.noise_strength * internal::SampleStd(x.data(), x.size());
  const Decomposition d = DecomposeWithNoise(x, w, o);
  bool some_mode_partly_reached = false;
  for (int m = 0; m < o.max_imfs; ++m) {
    long total = 0;
    int members = 0;
    for (int i = 0; i < 4; ++i) {
      const Decomposition e = Emd(x + amplitude * w.col(i), {}, o.max_imfs);
      if (m < e.num_imfs()) {
        total += e.report.sifts_per_imf[static_cast<size_t>(m)];
        ++members;
      }
    }
    some_mode_partly_reached |= members > 0 && members < 4;
    EXPECT_EQ(d.report.sifts_per_imf[static_cast<size_t>(m)],
              members == 0 ? 0 : std::lround(static_cast<double>(total) / members))
        << m;
  }
  EXPECT_TRUE(some_mode_partly_reached);  // the case under test happened
}

// EEMD is not complete, and what it misses is exactly the mean of the noise it added: each
// member is complete, so sum(modes) + residue = x + eps std(x) mean_i(w_i). Paired noise
// (w, -w; Yeh et al. 2010) therefore cancels to rounding.
TEST(Eemd, ReconstructionErrorIsTheMeanAddedNoise) {
  const Eigen::VectorXd x = Noisy(1024);
  const DecompositionOptions o = Eemd(4);
  const double amplitude = o.noise_strength * internal::SampleStd(x.data(), x.size());
  const double scale = x.cwiseAbs().maxCoeff();
  const Eigen::MatrixXd w = DrawnColumns(78, 4, 1024);
  const Decomposition d = DecomposeWithNoise(x, w, o);
  const Eigen::VectorXd error = d.imfs.rowwise().sum() + d.residue - x;
  const Eigen::VectorXd mean_noise = amplitude * w.rowwise().mean();
  EXPECT_GT(mean_noise.cwiseAbs().maxCoeff(), 1e-3 * scale);  // far from complete
  EXPECT_LE((error - mean_noise).cwiseAbs().maxCoeff(), 1e-12 * scale);

  Eigen::MatrixXd paired(1024, 4);
  paired << w.col(0), -w.col(0), w.col(1), -w.col(1);
  const Decomposition p = DecomposeWithNoise(x, paired, o);
  EXPECT_LE((p.imfs.rowwise().sum() + p.residue - x).cwiseAbs().maxCoeff(), 1e-12 * scale);
}

// The noise follows the signal's scale: 4x the signal (a power of two, so every rounding scales
// with it) gives 4x every mode, bit for bit.
TEST(Eemd, NoiseIsRelativeToTheSignalsStd) {
  const Eigen::VectorXd x = Noisy(512);
  const Decomposition d = Decompose(x, Eemd(3));
  const Decomposition d4 = Decompose(4.0 * x, Eemd(3));
  EXPECT_EQ(d4.imfs, 4.0 * d.imfs);
  EXPECT_EQ(d4.residue, 4.0 * d.residue);
}

}  // namespace
}  // namespace gyrodrift::decomposition
