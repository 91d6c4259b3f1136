// ICEEMDAN against the reference ceemdan.m (Colominas) + emd.m run with supplied noise
// (../shared/testdata/iceemdan_colominas/SOURCE.md): the signal and the noise are rebuilt here from
// the documented Lehmer/Box-Muller generators and passed through the supplied-noise option.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "gyrodrift/decomposition/decomposition.h"
#include "support/test_support.h"

namespace gyrodrift::decomposition {
namespace {

constexpr int kN = 1000;
constexpr int kRealisations = 20;

Eigen::VectorXd FixtureSignal() {
  const Eigen::VectorXd n = test::LehmerBoxMullerNormals(12345, kN);
  Eigen::VectorXd x(kN);
  for (int i = 0; i < kN; ++i) {
    const double di = i;
    x[i] = ((std::sin(((2 * std::numbers::pi) * di) / 50) +
             0.5 * std::sin(((2 * std::numbers::pi) * di) / 9)) +
            0.002 * di) +
           0.3 * n[i];
  }
  return x;
}

Eigen::VectorXd OctSines() {
  Eigen::VectorXd y(kN);
  for (int i = 0; i < kN; ++i) {
    double v = 0.002 * i;
    for (int k = 0; k < 9; ++k) v = v + std::sin(((2 * std::numbers::pi) * i) / (3 * std::pow(2.0, k)));
    y[i] = v;
  }
  return y;
}

std::shared_ptr<const Eigen::MatrixXd> FixtureNoise() {
  const Eigen::VectorXd g = test::LehmerBoxMullerNormals(67890, kN * kRealisations);
  auto w = std::make_shared<Eigen::MatrixXd>(kN, kRealisations);
  for (int r = 0; r < kRealisations; ++r) w->col(r) = g.segment(r * kN, kN);
  return w;
}

TEST(IceemdanReference, GeneratorsRebuildTheFixtureInputs) {
  const Eigen::MatrixXd x = test::ReadCsvMatrix(test::TestDataPath("iceemdan_colominas/x.csv"));
  EXPECT_LE((FixtureSignal() - x.col(2)).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::MatrixXd w = test::ReadCsvMatrix(test::TestDataPath("iceemdan_colominas/noise_W.csv"));
  EXPECT_LE((*FixtureNoise() - w).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::MatrixXd y = test::ReadCsvMatrix(test::TestDataPath("iceemdan_colominas/octsines_x.csv"));
  EXPECT_LE((OctSines() - y.col(1)).cwiseAbs().maxCoeff(), 1e-14);
}

struct Case {
  const char* name;
  bool octsines;
  NoiseScaling scaling;
  Method method;
  const char* modes_file;
  const char* sifts_file;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class IceemdanReference : public ::testing::TestWithParam<Case> {};

TEST_P(IceemdanReference, EveryModeMatches) {
  const Case& c = GetParam();
  DecompositionOptions o;
  o.method = c.method;
  o.beemdan_bound = BeemdanBound::kFull;  // BEEMDAN at full depth must equal ICEEMDAN
  o.noise_strength = 0.2;
  o.noise_scaling = c.scaling;
  o.sifting.max_sifts = 5000;
  const Decomposition d = DecomposeWithNoise(c.octsines ? OctSines() : FixtureSignal(),
                                             *FixtureNoise(), o, {.execution = {.threads = 2}});
  const Eigen::MatrixXd ref =
      test::ReadCsvMatrix(test::TestDataPath(std::string("iceemdan_colominas/") + c.modes_file));
  ASSERT_EQ(d.num_imfs() + 1, ref.cols()) << d.report.Summary();
  for (int k = 0; k < d.num_imfs(); ++k) {
    EXPECT_LE((d.imfs.col(k) - ref.col(k)).cwiseAbs().maxCoeff(), 1e-9) << "mode " << k + 1;
  }
  EXPECT_LE((d.residue - ref.col(ref.cols() - 1)).cwiseAbs().maxCoeff(), 1e-9);
  // Mean sift counts per stage equal the reference's (rounded the same way).
  const Eigen::MatrixXd sifts =
      test::ReadCsvMatrix(test::TestDataPath(std::string("iceemdan_colominas/") + c.sifts_file));
  for (int k = 0; k < d.num_imfs(); ++k) {
    EXPECT_EQ(d.report.sifts_per_imf[k], std::lround(sifts.col(k + 1).mean())) << "stage " << k + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, IceemdanReference,
    ::testing::Values(
        Case{"signal_snr1", false, NoiseScaling::kColominas2014, Method::kIceemdan,
             "iceemdan_snrflag1_modes.csv", "iceemdan_snrflag1_sifts.csv"},
        Case{"signal_snr2", false, NoiseScaling::kConstantSnr, Method::kIceemdan,
             "iceemdan_snrflag2_modes.csv", "iceemdan_snrflag2_sifts.csv"},
        Case{"octsines_snr1", true, NoiseScaling::kColominas2014, Method::kIceemdan,
             "octsines_iceemdan_snrflag1_modes.csv", "octsines_iceemdan_snrflag1_sifts.csv"},
        Case{"octsines_snr2", true, NoiseScaling::kConstantSnr, Method::kIceemdan,
             "octsines_iceemdan_snrflag2_modes.csv", "octsines_iceemdan_snrflag2_sifts.csv"},
        Case{"beemdan_full_signal_snr1", false, NoiseScaling::kColominas2014, Method::kBeemdan,
             "iceemdan_snrflag1_modes.csv", "iceemdan_snrflag1_sifts.csv"},
        Case{"beemdan_full_octsines_snr2", true, NoiseScaling::kConstantSnr, Method::kBeemdan,
             "octsines_iceemdan_snrflag2_modes.csv", "octsines_iceemdan_snrflag2_sifts.csv"}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace gyrodrift::decomposition
