// ICEEMDAN (src/decomposition/iceemdan.cc, Colominas, Schlotthauer & Torres 2014): residues are
// ensemble means of local means M(y) = y - E_1(y), r_1 = <M(x + beta_0 E_1(w_i))>,
// r_{k+1} = <M(r_k + beta_k E_{k+1}(w_i))>, modes are differences of residues, all on x / std(x).
// Checked here against a hand computation from plain EMD with supplied noise; the match with
// the authors' MATLAB code is tests/regression/decomposition/iceemdan_reference_test.cc.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "decomposition/drivers.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "unit/decomposition/hand_made.h"

namespace gyrodrift::decomposition {
namespace {

using hand_made::DrawnColumns;
using hand_made::LocalMean;
using hand_made::Std;

Eigen::VectorXd Noisy(Eigen::Index n) {
  Eigen::VectorXd x(n);
  Rng rng(61, 0);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = 0.4 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 30.0) +
           1.5 * std::sin(2 * std::numbers::pi * i / 200.0);
  }
  return x;
}

DecompositionOptions Iceemdan(NoiseScaling scaling) {
  DecompositionOptions o;
  o.method = Method::kIceemdan;
  o.noise_scaling = scaling;
  o.noise_strength = 0.25;
  o.max_imfs = 2;
  return o;
}

struct TwoStages {
  Eigen::VectorXd r1, r2;  // normalised residues
};

// The first two stages by hand, in iceemdan.cc's order of operations (so the sifts see the same
// bits): stage 1 adds eps E_1(w) / std(E_1(w)); stage 2 adds std(r_1) eps E_2(w), divided by
// std(E_2(w)) under the constant-SNR scaling only.
TwoStages ByHand(const Eigen::VectorXd& xn, const Eigen::MatrixXd& w, double eps,
                 NoiseScaling scaling) {
  const Eigen::Index n = xn.size();
  const double count = static_cast<double>(w.cols());
  TwoStages s{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n)};
  for (int i = 0; i < w.cols(); ++i) {
    const Decomposition noise = Emd(w.col(i));
    const Eigen::VectorXd e1 = noise.imfs.col(0);
    s.r1 += LocalMean(xn + (eps * e1) / Std(e1)) / count;
  }
  const double sr = Std(s.r1);
  for (int i = 0; i < w.cols(); ++i) {
    const Decomposition noise = Emd(w.col(i));
    const Eigen::VectorXd e2 = noise.imfs.col(1);
    const Eigen::VectorXd added = scaling == NoiseScaling::kConstantSnr
                                      ? Eigen::VectorXd(sr * (eps * (e2 / Std(e2))))
                                      : Eigen::VectorXd(sr * (eps * e2));
    s.r2 += LocalMean(s.r1 + added) / count;
  }
  return s;
}

class IceemdanByHand : public ::testing::TestWithParam<NoiseScaling> {};

TEST_P(IceemdanByHand, FirstTwoStagesAreMeansOfLocalMeans) {
  const Eigen::Index n = 800;
  const Eigen::VectorXd x = Noisy(n);
  const Eigen::MatrixXd w = DrawnColumns(93, 2, n);
  const DecompositionOptions o = Iceemdan(GetParam());
  const double sx = Std(x);
  const TwoStages s = ByHand(x / sx, w, o.noise_strength, GetParam());

  const Decomposition d = DecomposeWithNoise(x, w, o);
  ASSERT_EQ(d.num_imfs(), 2);
  const double tol = 1e-12 * x.cwiseAbs().maxCoeff();
  // Modes are differences of consecutive residues (d_1 = x - r_1), not means of IMFs.
  EXPECT_LE((d.imfs.col(0) - sx * (x / sx - s.r1)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.imfs.col(1) - sx * (s.r1 - s.r2)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.residue - sx * s.r2).cwiseAbs().maxCoeff(), tol);
  EXPECT_EQ(d.report.noise_assisted_stages, 2);
}

INSTANTIATE_TEST_SUITE_P(Scalings, IceemdanByHand,
                         ::testing::Values(NoiseScaling::kColominas2014,
                                           NoiseScaling::kConstantSnr),
                         [](const auto& info) {
                           return info.param == NoiseScaling::kColominas2014 ? "colominas2014"
                                                                             : "constant_snr";
                         });

// Both scalings normalise E_1 by its std at stage 1; they differ from stage 2 on only.
TEST(Iceemdan, NoiseScalingChangesOnlyTheLaterStages) {
  const Eigen::VectorXd x = Noisy(600);
  DecompositionOptions o = Iceemdan(NoiseScaling::kColominas2014);
  o.max_imfs = 0;
  o.ensemble_size = 4;
  const Decomposition a = Decompose(x, o);
  o.noise_scaling = NoiseScaling::kConstantSnr;
  const Decomposition b = Decompose(x, o);
  ASSERT_GE(a.num_imfs(), 2);
  ASSERT_GE(b.num_imfs(), 2);
  EXPECT_EQ(Eigen::VectorXd(a.imfs.col(0)), Eigen::VectorXd(b.imfs.col(0)));
  EXPECT_GT((a.imfs.col(1) - b.imfs.col(1)).cwiseAbs().maxCoeff(), 1e-6);
}

// The noise EMD's residue counts as its last mode. (-1)^i + 0.5 has one IMF, (-1)^i, and the
// residue 0.5: stage 2 then adds the constant std(r_1) eps 0.5, stage 3 and later no noise.
TEST(Iceemdan, TheNoiseResidueIsItsLastModeAndThenStagesGoWithoutNoise) {
  const Eigen::Index n = 700;
  const Eigen::VectorXd x = Noisy(n);
  Eigen::VectorXd w(n);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = (i % 2 ? -1.0 : 1.0) + 0.5;
  DecompositionOptions o = Iceemdan(NoiseScaling::kColominas2014);
  o.ensemble_size = 1;
  o.max_imfs = 0;
  const double eps = o.noise_strength;
  const double sx = Std(x);
  const Eigen::VectorXd xn = x / sx;
  Eigen::VectorXd e1(n);
  for (Eigen::Index i = 0; i < n; ++i) e1[i] = i % 2 ? -1.0 : 1.0;
  const Eigen::VectorXd r1 = LocalMean(xn + (eps * e1) / Std(e1));
  const double sr = Std(r1);
  const Eigen::VectorXd r2 = LocalMean((r1.array() + sr * (eps * 0.5)).matrix());
  // Without noise, r_{k+1} = M(r_k): the remaining modes are plain EMD of r_2.
  const Decomposition rest = Emd(r2);

  const Decomposition d = DecomposeWithNoise(x, w, o);
  ASSERT_EQ(d.num_imfs(), 2 + rest.num_imfs()) << d.report.Summary();
  const double tol = 1e-12 * x.cwiseAbs().maxCoeff();
  EXPECT_LE((d.imfs.col(0) - sx * (xn - r1)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((d.imfs.col(1) - sx * (r1 - r2)).cwiseAbs().maxCoeff(), tol);
  for (int k = 0; k < rest.num_imfs(); ++k) {
    EXPECT_LE((d.imfs.col(k + 2) - sx * rest.imfs.col(k)).cwiseAbs().maxCoeff(), tol) << k;
  }
  EXPECT_LE((d.residue - sx * rest.residue).cwiseAbs().maxCoeff(), tol);
  // The stages still count as noise-assisted: the ensemble ran them.
  EXPECT_EQ(d.report.noise_assisted_stages, d.num_imfs());
}

// beta_k = eps std(r_k): the noise follows the residue's scale, so scaling x by a power of two
// (exact in floating point) scales every mode by it, bit for bit.
TEST(Iceemdan, IsScaleEquivariant) {
  const Eigen::VectorXd x = Noisy(512);
  DecompositionOptions o = Iceemdan(NoiseScaling::kColominas2014);
  o.max_imfs = 0;
  o.ensemble_size = 3;
  const Decomposition d = Decompose(x, o);
  const Decomposition d8 = Decompose(8.0 * x, o);
  EXPECT_EQ(d8.imfs, 8.0 * d.imfs);
  EXPECT_EQ(d8.residue, 8.0 * d.residue);
}

}  // namespace
}  // namespace gyrodrift::decomposition
