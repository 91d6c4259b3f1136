// CEEMDAN (src/decomposition/ceemdan.cc, Torres et al. 2011): mode k is the ensemble mean of the
// first IMF of r_{k-1} + noise, on x normalised by its std; stage 1 adds eps w_i, stage k >= 2
// adds eps std(r_{k-1}) E_{k-1}(w_i) / std(E_{k-1}(w_i)). Checked here against a hand
// computation built from plain EMD; completeness and the rest of the family's properties are in
// tests/property/decomposition.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "decomposition/drivers.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "unit/decomposition/hand_made.h"

namespace gyrodrift::decomposition {
namespace {

using hand_made::Drawn;
using hand_made::FirstImf;
using hand_made::Std;

Eigen::VectorXd Noisy(Eigen::Index n) {
  Eigen::VectorXd x(n);
  Rng rng(51, 0);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = 3.0 + 0.4 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 40.0) + 0.002 * i;
  }
  return x;
}

DecompositionOptions Ceemdan(int ensemble) {
  DecompositionOptions o;
  o.method = Method::kCeemdan;
  o.ensemble_size = ensemble;
  o.seed = 3;
  return o;
}

// Mode 1 is the mean of E_1(x/std(x) + eps w_i) over the drawn realisations (w_i from stream
// (seed, i), unit variance, not rescaled), times std(x).
TEST(Ceemdan, FirstModeIsTheMeanFirstImfOfTheNoisyCopies) {
  const Eigen::Index n = 1024;
  const Eigen::VectorXd x = Noisy(n);
  const DecompositionOptions o = Ceemdan(3);
  const double sx = Std(x);
  const Eigen::VectorXd xn = x / sx;
  Eigen::VectorXd mode = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < 3; ++i) {
    mode += FirstImf(xn + o.noise_strength * Drawn(o.seed, i, n)) / 3.0;
  }
  const Decomposition d = Decompose(x, o);
  ASSERT_GE(d.num_imfs(), 2);
  EXPECT_LE((d.imfs.col(0) - sx * mode).cwiseAbs().maxCoeff(), 1e-12 * x.cwiseAbs().maxCoeff());
  EXPECT_EQ(d.report.method, Method::kCeemdan);
  EXPECT_EQ(d.report.noise_assisted_stages, d.num_imfs());  // CEEMDAN adds noise at every stage
}

// Stage 2 sifts r_1 + eps std(r_1) E_1(w_i) / std(E_1(w_i)): the noise's own first EMD mode,
// normalised, at a constant SNR against the residue. Two supplied realisations, by hand.
TEST(Ceemdan, SecondStageAddsTheNoisesFirstModeScaledToTheResidue) {
  const Eigen::Index n = 768;
  const Eigen::VectorXd x = Noisy(n);
  Eigen::MatrixXd w(n, 2);
  w << Drawn(91, 0, n), Drawn(91, 1, n);
  DecompositionOptions o = Ceemdan(2);
  o.max_imfs = 2;
  o.noise_strength = 0.3;
  const double eps = o.noise_strength;
  const double sx = Std(x);
  const Eigen::VectorXd xn = x / sx;

  Eigen::VectorXd mode1 = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < 2; ++i) mode1 += 0.5 * FirstImf(xn + eps * w.col(i));
  const Eigen::VectorXd r1 = xn - mode1;
  const double sr = Std(r1);
  Eigen::VectorXd mode2 = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < 2; ++i) {
    const Eigen::VectorXd e1 = FirstImf(w.col(i));
    // The operation order of ceemdan.cc, so that the sifts see the same bits.
    mode2 += 0.5 * FirstImf(r1 + sr * (eps * (e1 / Std(e1))));
  }

  const Decomposition d = DecomposeWithNoise(x, w, o);
  ASSERT_EQ(d.num_imfs(), 2);
  const double tol = 1e-12 * x.cwiseAbs().maxCoeff();
  EXPECT_LE((d.imfs.col(0) - sx * mode1).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.imfs.col(1) - sx * mode2).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.residue - sx * (r1 - mode2)).cwiseAbs().maxCoeff(), tol);
  EXPECT_TRUE(d.report.supplied_noise);
  EXPECT_EQ(d.report.ensemble_size, 2);
}

// A realisation whose noise EMD has run out of rows contributes the residue's first IMF without
// noise. (-1)^i is a single IMF with a zero residue: with it as the only realisation, stage 1
// adds it, stage 2 adds it again as E_1 (normalised), and every later stage is plain EMD of r_2.
TEST(Ceemdan, StagesWithoutNoiseRowsArePlainEmdOfTheResidue) {
  const Eigen::Index n = 1000;
  const Eigen::VectorXd x = Noisy(n);
  Eigen::VectorXd alternating(n);
  for (Eigen::Index i = 0; i < n; ++i) alternating[i] = i % 2 ? -1.0 : 1.0;
  const DecompositionOptions o = Ceemdan(1);
  const double eps = o.noise_strength;
  const double sx = Std(x);
  const Eigen::VectorXd xn = x / sx;
  const Eigen::VectorXd mode1 = FirstImf(xn + eps * alternating);
  const Eigen::VectorXd r1 = xn - mode1;
  const Eigen::VectorXd mode2 = FirstImf(r1 + Std(r1) * (eps * (alternating / Std(alternating))));
  const Eigen::VectorXd r2 = r1 - mode2;
  const Decomposition rest = Emd(r2);

  const Decomposition d = DecomposeWithNoise(x, alternating, o);
  ASSERT_EQ(d.num_imfs(), rest.num_imfs() + 2) << d.report.Summary();
  const double tol = 1e-12 * x.cwiseAbs().maxCoeff();
  EXPECT_LE((d.imfs.col(0) - sx * mode1).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.imfs.col(1) - sx * mode2).cwiseAbs().maxCoeff(), tol);
  for (int k = 0; k < rest.num_imfs(); ++k) {
    EXPECT_LE((d.imfs.col(k + 2) - sx * rest.imfs.col(k)).cwiseAbs().maxCoeff(), tol) << k;
  }
  EXPECT_LE((d.residue - sx * rest.residue).cwiseAbs().maxCoeff(), tol);
}

}  // namespace
}  // namespace gyrodrift::decomposition
