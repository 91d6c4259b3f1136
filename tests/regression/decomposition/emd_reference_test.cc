// EMD against Rilling & Flandrin's MATLAB emd.m: the Doppler signal (4096 samples, EMD.jl
// fixture) and the ICEEMDAN fixture's plain EMD (Octave). Tolerances from the SOURCE.md files.
#include <gtest/gtest.h>

#include "gyrodrift/decomposition/decomposition.h"
#include "support/test_support.h"

namespace gyrodrift::decomposition {
namespace {

TEST(EmdReference, DopplerMatchesMatlabEmd) {
  const Eigen::VectorXd x =
      test::ReadF64(test::TestDataPath("emd_rilling_doppler/doppler4096_f64le.bin"));
  const Eigen::VectorXd ref =
      test::ReadF64(test::TestDataPath("emd_rilling_doppler/imf4096x4_colmajor_f64le.bin"));
  ASSERT_EQ(x.size(), 4096);
  const Decomposition d = Emd(x);
  ASSERT_EQ(d.num_imfs(), 3) << d.report.Summary();
  for (int k = 0; k < 4; ++k) {
    const Eigen::VectorXd expected = ref.segment(k * 4096, 4096);
    const Eigen::VectorXd actual = k < 3 ? Eigen::VectorXd(d.imfs.col(k)) : d.residue;
    const double scale = expected.cwiseAbs().maxCoeff();
    EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), 1e-8 * scale) << "row " << k;
  }
}

TEST(EmdReference, IceemdanFixtureSignalMatchesOctaveEmd) {
  const Eigen::MatrixXd input = test::ReadCsvMatrix(test::TestDataPath("iceemdan_colominas/x.csv"));
  const Eigen::MatrixXd ref =
      test::ReadCsvMatrix(test::TestDataPath("iceemdan_colominas/emd_rilling_modes.csv"));
  const Decomposition d = Emd(input.col(2));
  ASSERT_EQ(d.num_imfs(), 5) << d.report.Summary();
  EXPECT_EQ(d.report.sifts_per_imf, (std::vector<int>{11, 5, 18, 4, 3}));
  for (int k = 0; k < 5; ++k) {
    EXPECT_LE((d.imfs.col(k) - ref.col(k)).cwiseAbs().maxCoeff(), 1e-9) << "IMF " << k + 1;
  }
  EXPECT_LE((d.residue - ref.col(5)).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace gyrodrift::decomposition
