// The correlation model of overlapping Allan-variance estimates (src/allan/avar_correlation.h)
// against Monte Carlo: many independent records of white rate noise, random-walk rate and white
// angle noise, their OADEV at octave factors, and the empirical correlation of the variances.
#include "allan/avar_correlation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::allan {
namespace {

enum class Noise { kWhiteRate, kRandomWalkRate, kWhiteAngle };

struct MonteCarlo {
  Eigen::MatrixXd correlation;  // empirical, of the AVAR estimates
  Eigen::VectorXd m, n_terms;
};

MonteCarlo Simulate(Noise noise, int records, Eigen::Index length) {
  AllanOptions o{.grid = TauGrid::kOctave, .confidence_intervals = false};
  Eigen::MatrixXd avar;
  MonteCarlo mc;
  Eigen::VectorXd white(length + 1), y(length);
  for (int r = 0; r < records; ++r) {
    Rng rng(77, static_cast<std::uint64_t>(r));
    rng.FillNormal(white);
    double walk = 0.0;
    for (Eigen::Index k = 0; k < length; ++k) {
      switch (noise) {
        case Noise::kWhiteRate:
          y[k] = white[k];
          break;
        case Noise::kRandomWalkRate:
          y[k] = walk += white[k];
          break;
        case Noise::kWhiteAngle:
          y[k] = white[k + 1] - white[k];
          break;
      }
    }
    const AllanResult result = Compute(y, o, {.threads = 1});
    const auto t = static_cast<Eigen::Index>(result.points.size());
    if (r == 0) {
      avar.resize(records, t);
      mc.m.resize(t);
      mc.n_terms.resize(t);
      for (Eigen::Index i = 0; i < t; ++i) {
        mc.m[i] = static_cast<double>(result.points[static_cast<size_t>(i)].m);
        mc.n_terms[i] = static_cast<double>(result.points[static_cast<size_t>(i)].n_terms);
      }
    }
    for (Eigen::Index i = 0; i < t; ++i) {
      const double dev = result.points[static_cast<size_t>(i)].dev;
      avar(r, i) = dev * dev;
    }
  }
  const Eigen::MatrixXd centred = avar.rowwise() - avar.colwise().mean();
  const Eigen::MatrixXd cov = centred.transpose() * centred / (records - 1.0);
  const Eigen::VectorXd inv_sd = cov.diagonal().cwiseSqrt().cwiseInverse();
  mc.correlation = inv_sd.asDiagonal() * cov * inv_sd.asDiagonal();
  return mc;
}

class AvarCorrelationMc : public ::testing::TestWithParam<Noise> {};

// Octave factors 1..256 of 4096-sample records (so every estimate has at least 3584 terms and
// the long-record theory applies), 1500 records: the standard error of an empirical correlation
// is (1 - rho^2) / sqrt(1500) <= 0.026; the bound is 4 of those.
TEST_P(AvarCorrelationMc, MatchesMonteCarlo) {
  const MonteCarlo mc = Simulate(GetParam(), 1500, 4096);
  std::array<double, 5> coef{};
  coef[GetParam() == Noise::kWhiteRate ? 1 : GetParam() == Noise::kRandomWalkRate ? 3 : 0] = 1.0;
  // Only the factors up to 256 (the theory assumes many terms per estimate).
  Eigen::Index t = 0;
  while (t < mc.m.size() && mc.m[t] <= 256) ++t;
  ASSERT_GE(t, 8);
  const Eigen::MatrixXd model =
      AvarCorrelation(mc.m.head(t), coef, 1.0, mc.n_terms.head(t));
  double largest_neighbour = 0.0;
  for (Eigen::Index i = 0; i < t; ++i) {
    EXPECT_EQ(model(i, i), 1.0);
    for (Eigen::Index j = i + 1; j < t; ++j) {
      EXPECT_EQ(model(i, j), model(j, i));
      EXPECT_NEAR(model(i, j), mc.correlation(i, j), 0.1)
          << "m " << mc.m[i] << " and " << mc.m[j];
    }
    if (i + 1 < t) largest_neighbour = std::max(largest_neighbour, model(i, i + 1));
  }
  // The point of the model: octave neighbours are far from independent.
  EXPECT_GT(largest_neighbour, 0.3);
}

INSTANTIATE_TEST_SUITE_P(NoiseTypes, AvarCorrelationMc,
                         ::testing::Values(Noise::kWhiteRate, Noise::kRandomWalkRate,
                                           Noise::kWhiteAngle),
                         [](const auto& info) {
                           return info.param == Noise::kWhiteRate        ? "WhiteRate"
                                  : info.param == Noise::kRandomWalkRate ? "RandomWalkRate"
                                                                         : "WhiteAngle";
                         });

// Same factors, longer record: the correlation model does not depend on the record length
// except through the term counts.
TEST(AvarCorrelation, IndependentOfScaleForPowerLawsAndZeroSpectrumGivesIdentity) {
  Eigen::VectorXd m(4), m10(4);
  m << 1, 2, 4, 8;
  m10 = 16 * m;
  const std::array<double, 5> flicker{0, 0, 1, 0, 0};
  const Eigen::MatrixXd a = AvarCorrelation(m10, flicker, 1.0, Eigen::VectorXd());
  const Eigen::MatrixXd b = AvarCorrelation(2 * m10, flicker, 1.0, Eigen::VectorXd());
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 0.02);
  EXPECT_EQ(AvarCorrelation(m, {}, 1.0, Eigen::VectorXd()), Eigen::MatrixXd::Identity(4, 4));
}

}  // namespace
}  // namespace gyrodrift::allan
