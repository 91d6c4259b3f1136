// What the noise-assisted decompositions share (src/decomposition/noise_ensemble.h): the report
// of the threads used, the stage-end checks, and realisation i's noise and its EMD rows, drawn
// on demand or read from shared NoiseEmds alike.
#include "decomposition/noise_ensemble.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition::internal {
namespace {

Eigen::VectorXd Signal(Eigen::Index n) {
  Eigen::VectorXd x(n);
  Rng rng(9, 0);
  for (Eigen::Index t = 0; t < n; ++t) x[t] = std::sin(0.05 * t) + 0.3 * rng.Normal();
  return x;
}

TEST(NoiseEnsemble, ReportsTheThreadsUsedAndNeverMoreThanTheRealisations) {
  const Eigen::VectorXd x = Signal(600);
  DecompositionOptions o;
  o.method = Method::kCeemdan;
  o.ensemble_size = 3;
  const Decomposition many = Decompose(x, o, {.execution = {.threads = 8}});
  EXPECT_EQ(many.report.threads, 3);  // 3 realisations keep at most 3 workers busy
  const Decomposition one = Decompose(x, o, {.execution = {.threads = 1}});
  EXPECT_EQ(one.report.threads, 1);
  EXPECT_EQ(one.imfs, many.imfs);  // and the count never changes a result
  EXPECT_EQ(one.report.Summary(), many.report.Summary());
  o.method = Method::kEmd;
  EXPECT_EQ(Decompose(x, o, {.execution = {.threads = 8}}).report.threads, 1);
}

TEST(NoiseEnsemble, StagesEndAtTheImfCapOrAResidueWithoutThreeExtrema) {
  DecompositionOptions o;
  DecompositionReport report;
  const Eigen::VectorXd wavy = Signal(200);
  EXPECT_FALSE(StagesEnd(o, 5, wavy, true, report));
  o.max_imfs = 5;
  EXPECT_TRUE(StagesEnd(o, 5, wavy, true, report));
  EXPECT_EQ(report.stop_reason, "IMF cap (5) reached");
  o.max_imfs = 0;
  Eigen::VectorXd ramp(200);
  for (Eigen::Index t = 0; t < 200; ++t) ramp[t] = 0.1 * t;
  EXPECT_FALSE(StagesEnd(o, 1, ramp, false, report));  // stage 0 does not look at extrema
  EXPECT_TRUE(StagesEnd(o, 1, ramp, true, report));
  EXPECT_EQ(report.stop_reason, "residue has fewer than 3 extrema");
}

TEST(NoiseEnsemble, RowsAreTheSameDrawnOnDemandOrReadFromSharedNoiseEmds) {
  const Eigen::Index n = 300;
  DecompositionOptions o;
  o.method = Method::kIceemdan;
  o.ensemble_size = 4;
  o.seed = 11;
  const DecompositionContext own;
  DecompositionContext shared;
  shared.noise_emds = std::make_shared<const NoiseEmds>(n, o);
  Sifter sifter(n, o.sifting);
  Eigen::VectorXd a(n), b(n);
  for (int i = 0; i < o.ensemble_size; ++i) {
    NoiseRows drawn(Job{o, own}, i, n), read(Job{o, shared}, i, n);
    EXPECT_EQ(drawn.white(), read.white()) << i;
    Rng rng(o.seed, static_cast<std::uint64_t>(i));  // realisation i is stream (seed, i)
    Eigen::VectorXd expected(n);
    rng.FillNormal(expected);
    EXPECT_EQ(drawn.white(), expected) << i;
    int rows = 0;
    while (drawn.Next(sifter, a.data())) {
      ASSERT_TRUE(read.Next(sifter, b.data())) << i << " row " << rows;
      EXPECT_EQ(a, b) << i << " row " << rows;
      EXPECT_EQ(drawn.last_imf(), read.last_imf());
      ++rows;
    }
    EXPECT_FALSE(read.Next(sifter, b.data()));
    EXPECT_GE(rows, 3) << i;
  }
}

}  // namespace
}  // namespace gyrodrift::decomposition::internal
