// The white-noise self-similarity level: seeded, independent of the thread count, cached,
// white-noise IMFs stay under it while a sinusoid does not, and the family-wise level of modes
// tested together passes white records at its confidence.
#include "gyrodrift/selection/noise_level.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::selection {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kLength = 2048;

MonteCarloOptions SmallRun(std::uint64_t seed = 1) {
  MonteCarloOptions o;
  o.realisations = 40;
  o.seed = seed;
  return o;
}

Execution Threads(int threads) { return {.threads = threads}; }

// Bitwise equality of two level vectors (NaN entries included).
bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(SelfSimilarity, AffineInvariantAndSmallForGaussianSamples) {
  Eigen::VectorXd x(20000);
  Rng(5, 0).FillNormal(x);
  const double g = SelfSimilarityDistance(x, {}, PdfDistance::kL2);
  EXPECT_LT(g, 0.02);
  const Eigen::VectorXd y = (3.0 * x.array() + 100.0).matrix();
  EXPECT_NEAR(SelfSimilarityDistance(y, {}, PdfDistance::kL2), g, 1e-9);
  Eigen::VectorXd sine(20000);
  for (int t = 0; t < 20000; ++t) sine[t] = std::sin(2 * kPi * t / 500.0);
  EXPECT_GT(SelfSimilarityDistance(sine, {}, PdfDistance::kL2), 10 * g);
  EXPECT_EQ(SelfSimilarityDistance(Eigen::VectorXd::Constant(100, 2.0), {}, PdfDistance::kL2),
            std::numeric_limits<double>::infinity());
}

TEST(NoiseLevel, SeededAndThreadCountIndependent) {
  const NoiseLevel one = ComputeNoiseLevel(kLength, SmallRun(), {}, PdfDistance::kL2, Threads(1));
  const NoiseLevel two = ComputeNoiseLevel(kLength, SmallRun(), {}, PdfDistance::kL2, Threads(2));
  const NoiseLevel again = ComputeNoiseLevel(kLength, SmallRun(), {}, PdfDistance::kL2, Threads(2));
  EXPECT_TRUE(SameBits(one.level, two.level));
  EXPECT_TRUE(SameBits(two.level, again.level));
  EXPECT_EQ(one.realisations_with_mode, two.realisations_with_mode);
  const NoiseLevel other =
      ComputeNoiseLevel(kLength, SmallRun(2), {}, PdfDistance::kL2, Threads(2));
  EXPECT_FALSE(SameBits(one.level, other.level));
  ASSERT_GE(one.level.size(), 5u);
  for (int k = 1; k <= 5; ++k) {
    EXPECT_TRUE(std::isfinite(one.LevelFor(k))) << k;
    EXPECT_GT(one.LevelFor(k), 0.0) << k;
    EXPECT_EQ(one.realisations_with_mode[static_cast<size_t>(k - 1)], 40) << k;
  }
  EXPECT_TRUE(std::isnan(one.LevelFor(0)));
  EXPECT_TRUE(std::isnan(one.LevelFor(100)));
  EXPECT_NE(one.Summary().find("N=2048 R=40"), std::string::npos) << one.Summary();
}

TEST(NoiseLevel, FreshWhiteNoiseModesStayUnderTheLevelSinusoidsDoNot) {
  const NoiseLevel level = ComputeNoiseLevel(kLength, SmallRun(), {}, PdfDistance::kL2);
  int under = 0, tested = 0;
  for (int i = 0; i < 20; ++i) {
    Eigen::VectorXd w(kLength);
    Rng(999, static_cast<std::uint64_t>(i)).FillNormal(w);  // not the Monte-Carlo's streams
    const decomposition::Decomposition d = decomposition::Emd(w);
    for (int k = 1; k <= 4; ++k) {
      ++tested;
      under += SelfSimilarityDistance(d.imfs.col(k - 1), {}, PdfDistance::kL2) <= level.LevelFor(k);
    }
  }
  EXPECT_GE(under, 0.85 * tested) << under << " of " << tested;
  Eigen::VectorXd sine(kLength);
  for (int t = 0; t < kLength; ++t) sine[t] = std::sin(2 * kPi * t / 40.0);
  for (int k = 1; k <= 4; ++k) {
    EXPECT_GT(SelfSimilarityDistance(sine, {}, PdfDistance::kL2), level.LevelFor(k)) << k;
  }
}

// Type-7 quantile, as the level's.
double Quantile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  if (lo + 1 >= v.size()) return v.back();
  return v[lo] + (pos - lo) * (v[lo + 1] - v[lo]);
}

// The family-wise level recomputed from the same realisations: median_k + c_m MAD_k, c_m the
// confidence quantile of each realisation's max over modes 1..m of (G_k - median_k) / MAD_k.
TEST(NoiseLevel, FamilyLevelIsTheMaxStatisticOfTheRealisations) {
  const MonteCarloOptions mc = SmallRun();
  const NoiseLevel level = ComputeNoiseLevel(kLength, mc, {}, PdfDistance::kL2);
  constexpr int kModes = 5;  // every realisation of 2048 samples has them
  std::vector<std::vector<double>> g(kModes);
  for (int i = 0; i < mc.realisations; ++i) {
    Eigen::VectorXd w(kLength);
    Rng(mc.seed, static_cast<std::uint64_t>(i)).FillNormal(w);
    const decomposition::Decomposition d = decomposition::Emd(w, mc.sifting);
    ASSERT_GE(d.num_imfs(), kModes);
    for (int k = 0; k < kModes; ++k) {
      g[k].push_back(SelfSimilarityDistance(d.imfs.col(k), {}, PdfDistance::kL2));
    }
  }
  std::vector<double> running(static_cast<size_t>(mc.realisations), -1e300);
  for (int k = 0; k < kModes; ++k) {
    const double median = Quantile(g[k], 0.5);
    std::vector<double> deviation;
    for (double v : g[k]) deviation.push_back(std::abs(v - median));
    const double mad = Quantile(deviation, 0.5);
    EXPECT_NEAR(level.median[k], median, 1e-12) << k;
    EXPECT_NEAR(level.mad[k], mad, 1e-12) << k;
    for (size_t i = 0; i < running.size(); ++i) {
      running[i] = std::max(running[i], (g[k][i] - median) / mad);
    }
    EXPECT_NEAR(level.family_scale[k], Quantile(running, mc.confidence), 1e-9) << k;
    EXPECT_DOUBLE_EQ(level.FamilyLevelFor(k + 1, kModes),
                     level.median[k] + level.family_scale[kModes - 1] * level.mad[k]);
  }
  // A larger family never lowers the level.
  for (size_t m = 1; m < level.family_scale.size(); ++m) {
    EXPECT_GE(level.family_scale[m], level.family_scale[m - 1]) << m;
  }
  EXPECT_TRUE(std::isnan(level.FamilyLevelFor(0, 3)));
  EXPECT_TRUE(std::isnan(level.FamilyLevelFor(4, 3)));  // mode outside the family
  EXPECT_TRUE(std::isnan(level.FamilyLevelFor(1, 100)));
}

// Fresh white noise (other streams) passes modes 1..m together at about the confidence; each
// mode's own 99 % level, asked m times, fails several times as many records.
TEST(NoiseLevel, FamilyLevelPassesWhiteRecordsAtItsConfidence) {
  constexpr int kN = 1024;
  constexpr int kModes = 7;
  constexpr int kRecords = 200;
  MonteCarloOptions mc;  // 100 realisations, 99 %
  const NoiseLevel level = ComputeNoiseLevel(kN, mc, {}, PdfDistance::kL2);
  int family_pass = 0, single_pass = 0;
  for (int i = 0; i < kRecords; ++i) {
    Eigen::VectorXd w(kN);
    Rng(4242, static_cast<std::uint64_t>(i)).FillNormal(w);
    const decomposition::Decomposition d = decomposition::Emd(w);
    ASSERT_GE(d.num_imfs(), kModes);
    bool family = true, single = true;
    for (int k = 1; k <= kModes; ++k) {
      const double gk = SelfSimilarityDistance(d.imfs.col(k - 1), {}, PdfDistance::kL2);
      family = family && gk <= level.FamilyLevelFor(k, kModes);
      single = single && gk <= level.LevelFor(k);
    }
    family_pass += family;
    single_pass += single;
  }
  EXPECT_GE(family_pass, 0.96 * kRecords) << single_pass;
  EXPECT_GE(kRecords - single_pass, 2 * (kRecords - family_pass)) << family_pass;
  EXPECT_LE(single_pass, 0.96 * kRecords) << family_pass;
}

TEST(NoiseLevelCache, SecondCallIsCachedAndIdentical) {
  NoiseLevelCache cache;
  bool computed = false;
  const auto t0 = std::chrono::steady_clock::now();
  const auto first = cache.Get(kLength, SmallRun(), {}, PdfDistance::kL2, &computed);
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_TRUE(computed);
  const auto second = cache.Get(kLength, SmallRun(), {}, PdfDistance::kL2, &computed, Threads(2));
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_FALSE(computed);  // the thread count is not part of the key
  EXPECT_EQ(first.get(), second.get());
  EXPECT_LT((t2 - t1).count() * 20, (t1 - t0).count());
  EXPECT_TRUE(
      SameBits(first->level, ComputeNoiseLevel(kLength, SmallRun(), {}, PdfDistance::kL2).level));
  // Another seed, distance or grid is another entry.
  cache.Get(kLength, SmallRun(3), {}, PdfDistance::kL2, &computed);
  EXPECT_TRUE(computed);
  cache.Get(kLength, SmallRun(), {}, PdfDistance::kHellinger, &computed);
  EXPECT_TRUE(computed);
  cache.Get(kLength, SmallRun(), KdeOptions{.grid_points = 256}, PdfDistance::kL2, &computed);
  EXPECT_TRUE(computed);
  EXPECT_EQ(cache.Size(), 4u);
  cache.Clear();
  EXPECT_EQ(cache.Size(), 0u);
}

TEST(NoiseLevelCache, ConcurrentCallersShareOneComputation) {
  NoiseLevelCache cache;
  std::shared_ptr<const NoiseLevel> a, b, c;
  bool ca = false, cb = false, cc = false;
  std::thread ta([&] { a = cache.Get(1024, SmallRun(), {}, PdfDistance::kL2, &ca, Threads(1)); });
  std::thread tb([&] { b = cache.Get(1024, SmallRun(), {}, PdfDistance::kL2, &cb, Threads(1)); });
  std::thread tc([&] { c = cache.Get(1024, SmallRun(), {}, PdfDistance::kL2, &cc, Threads(1)); });
  ta.join();
  tb.join();
  tc.join();
  EXPECT_EQ(a.get(), b.get());
  EXPECT_EQ(a.get(), c.get());
  EXPECT_EQ(ca + cb + cc, 1);
}

// A slow sinusoid in white noise, decomposed by a CEEMDAN-family method with the Monte-Carlo's
// realisation count.
struct Decomposed {
  Eigen::VectorXd x;
  decomposition::Decomposition d;
  std::shared_ptr<const NoiseLevel> level;
  bool attached = false;
};
Decomposed DecomposeWithCollector(const decomposition::DecompositionOptions& o,
                                  const MonteCarloOptions& mc, int threads,
                                  decomposition::DecompositionContext context = {}) {
  Decomposed out;
  out.x.resize(kLength);
  Rng(11, 0).FillNormal(out.x);
  for (int t = 0; t < kLength; ++t) out.x[t] += 3.0 * std::sin(2 * kPi * t / 700.0);
  NoiseLevelCollector collector(kLength, mc, {}, PdfDistance::kL2);
  context.execution.threads = threads;
  out.attached = collector.Attach(o, &context);
  out.d = decomposition::Decompose(out.x, o, context);
  out.level = collector.Level();
  return out;
}

decomposition::DecompositionOptions FamilyRun(decomposition::Method method) {
  decomposition::DecompositionOptions o;
  o.method = method;
  o.ensemble_size = 40;
  o.seed = 5;
  return o;
}

TEST(NoiseLevelCollector, EqualsTheMonteCarloForTheModesTheDecompositionReached) {
  const NoiseLevel mc = ComputeNoiseLevel(kLength, SmallRun(5), {}, PdfDistance::kL2);
  for (auto method : {decomposition::Method::kCeemdan, decomposition::Method::kIceemdan,
                      decomposition::Method::kBeemdan}) {
    const std::string name(decomposition::ToString(method));
    for (int threads : {1, 2}) {
      const Decomposed run = DecomposeWithCollector(FamilyRun(method), SmallRun(1), threads);
      ASSERT_TRUE(run.attached) << name;
      ASSERT_TRUE(run.level) << name;
      const NoiseLevel& level = *run.level;
      EXPECT_TRUE(level.partial);
      EXPECT_EQ(level.seed, 5u);  // the decomposition's seed, not the Monte-Carlo's
      EXPECT_EQ(level.realisations, 40);
      ASSERT_GE(level.level.size(), 3u) << name;
      ASSERT_LE(level.level.size(), mc.level.size()) << name;
      const size_t d = level.level.size();
      EXPECT_TRUE(SameBits(level.level, {mc.level.begin(), mc.level.begin() + d})) << name;
      EXPECT_TRUE(SameBits(level.median, {mc.median.begin(), mc.median.begin() + d})) << name;
      EXPECT_EQ(level.realisations_with_mode,
                std::vector<int>(mc.realisations_with_mode.begin(),
                                 mc.realisations_with_mode.begin() + d))
          << name;
    }
  }
  // BEEMDAN with 2 noise-assisted stages reaches noise mode 2 only.
  decomposition::DecompositionOptions bounded = FamilyRun(decomposition::Method::kBeemdan);
  bounded.beemdan_bound = decomposition::BeemdanBound::kFixedStages;
  bounded.noise_stages = 2;
  const Decomposed run = DecomposeWithCollector(bounded, SmallRun(), 2);
  ASSERT_TRUE(run.level);
  EXPECT_EQ(run.level->level.size(), 2u);
}

TEST(NoiseLevelCollector, StaysOutWhenTheNoiseIsNotTheMonteCarlos) {
  using decomposition::Method;
  auto refused = [](const decomposition::DecompositionOptions& o, const MonteCarloOptions& mc,
                    decomposition::DecompositionContext context = {}) {
    const Decomposed run = DecomposeWithCollector(o, mc, 2, std::move(context));
    return !run.attached && !run.level;
  };
  EXPECT_TRUE(refused(FamilyRun(Method::kEemd), SmallRun()));
  EXPECT_TRUE(refused(FamilyRun(Method::kEmd), SmallRun()));
  decomposition::DecompositionOptions few = FamilyRun(Method::kIceemdan);
  few.ensemble_size = 39;
  EXPECT_TRUE(refused(few, SmallRun()));
  decomposition::DecompositionOptions snumber = FamilyRun(Method::kIceemdan);
  snumber.sifting.stop_rule = decomposition::StopRule::kSNumber;
  EXPECT_TRUE(refused(snumber, SmallRun()));
  MonteCarloOptions capped = SmallRun();
  capped.max_imfs = 3;
  EXPECT_TRUE(refused(FamilyRun(Method::kIceemdan), capped));
  // Another observer holds the context's place.
  decomposition::DecompositionContext observed;
  observed.noise_imf_observer = [](int, int, const double*) {};
  EXPECT_TRUE(refused(FamilyRun(Method::kIceemdan), SmallRun(), observed));
}

TEST(NoiseLevel, RejectsBadOptions) {
  MonteCarloOptions few = SmallRun();
  few.realisations = 5;
  EXPECT_THROW(ComputeNoiseLevel(kLength, few, {}, PdfDistance::kL2), UsageError);
  MonteCarloOptions certain = SmallRun();
  certain.confidence = 1.0;
  EXPECT_THROW(ComputeNoiseLevel(kLength, certain, {}, PdfDistance::kL2), UsageError);
  EXPECT_THROW(ComputeNoiseLevel(8, SmallRun(), {}, PdfDistance::kL2), UsageError);
  EXPECT_THROW(
      ComputeNoiseLevel(kLength, SmallRun(), KdeOptions{.grid_points = 10}, PdfDistance::kL2),
      UsageError);
  NoiseLevelCache cache;
  EXPECT_THROW(cache.Get(kLength, SmallRun(), {}, PdfDistance::kL2, nullptr, Threads(-1)),
               UsageError);
  EXPECT_EQ(cache.Size(), 0u);
}

}  // namespace
}  // namespace gyrodrift::selection
