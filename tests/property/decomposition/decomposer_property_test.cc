// One property tester run over the whole EMD family (STYLE.md: manif/Sophus common_tester).
// Every property is one that a broken decomposer would fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition {
namespace {

Eigen::VectorXd Noisy(Eigen::Index n, std::uint64_t seed) {
  Rng rng(seed, 0);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = 0.5 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 64.0) + 0.01 * i;
  }
  return x;
}

DecompositionOptions Options(Method method) {
  DecompositionOptions o;
  o.method = method;
  o.ensemble_size = 16;  // small ensembles keep the suite fast; properties do not depend on I
  o.seed = 7;
  return o;
}

const DecompositionContext kOneThread{.execution = {.threads = 1}};
DecompositionContext Threads(int threads) { return {.execution = {.threads = threads}}; }

class Decomposer : public ::testing::TestWithParam<Method> {};

TEST_P(Decomposer, CompletenessAndShape) {
  const Eigen::VectorXd x = Noisy(1024, 1);
  const Eigen::VectorXd copy = x;
  const Decomposition d = Decompose(x, Options(GetParam()), kOneThread);
  EXPECT_EQ(x, copy) << "input modified";
  ASSERT_EQ(d.imfs.rows(), x.size());
  ASSERT_EQ(d.residue.size(), x.size());
  ASSERT_GE(d.num_imfs(), 3);
  ASSERT_TRUE(d.imfs.allFinite());
  const Eigen::VectorXd sum = d.imfs.rowwise().sum() + d.residue;
  const double error = (sum - x).cwiseAbs().maxCoeff() / x.cwiseAbs().maxCoeff();
  if (GetParam() == Method::kEemd) {
    // EEMD is not complete: the mean of I noise copies remains, std about eps std(x)/sqrt(I).
    Eigen::VectorXd centred = x.array() - x.mean();
    const double sx = std::sqrt(centred.squaredNorm() / (x.size() - 1));
    const double rms = std::sqrt((sum - x).squaredNorm() / x.size());
    EXPECT_NEAR(rms, 0.2 * sx / std::sqrt(16.0), 0.3 * 0.2 * sx / std::sqrt(16.0));
  } else {
    EXPECT_LE(error, 1e-12);
  }
}

TEST_P(Decomposer, EemdErrorShrinksLikeOneOverSqrtI) {
  if (GetParam() != Method::kEemd) GTEST_SKIP() << "EEMD only";
  const Eigen::VectorXd x = Noisy(1024, 2);
  double rms[2];
  int sizes[2] = {4, 64};
  for (int k = 0; k < 2; ++k) {
    DecompositionOptions o = Options(Method::kEemd);
    o.ensemble_size = sizes[k];
    const Decomposition d = Decompose(x, o, kOneThread);
    rms[k] = std::sqrt((d.imfs.rowwise().sum() + d.residue - x).squaredNorm() / x.size());
  }
  // 16x the members: 4x smaller error (within sampling scatter).
  EXPECT_NEAR(rms[0] / rms[1], 4.0, 1.2);
}

TEST_P(Decomposer, ImfCapIsRespected) {
  DecompositionOptions o = Options(GetParam());
  o.max_imfs = 2;
  const Decomposition d = Decompose(Noisy(512, 3), o, kOneThread);
  EXPECT_EQ(d.num_imfs(), 2);
  if (GetParam() != Method::kEemd) {
    const Eigen::VectorXd x = Noisy(512, 3);
    EXPECT_LE((d.imfs.rowwise().sum() + d.residue - x).cwiseAbs().maxCoeff(),
              1e-12 * x.cwiseAbs().maxCoeff());
  }
}

TEST_P(Decomposer, SameSeedSameBitsAndThreadCountDoesNotMatter) {
  const Eigen::VectorXd x = Noisy(777, 4);
  DecompositionOptions o = Options(GetParam());
  const Decomposition a = Decompose(x, o, kOneThread);
  const Decomposition b = Decompose(x, o, kOneThread);
  const Decomposition c = Decompose(x, o, Threads(2));
  const Decomposition e = Decompose(x, o, Threads(3));
  EXPECT_EQ(a.imfs, b.imfs);
  EXPECT_EQ(a.imfs, c.imfs);
  EXPECT_EQ(a.residue, c.residue);
  EXPECT_EQ(a.imfs, e.imfs);
  if (GetParam() != Method::kEmd) {
    o.seed = 8;
    const Decomposition other = Decompose(x, o, kOneThread);
    EXPECT_FALSE(a.imfs.cols() == other.imfs.cols() && a.imfs == other.imfs) << "seed ignored";
  }
}

TEST_P(Decomposer, ConstantAndLinearInputsHaveNoOscillatingImf) {
  for (const double slope : {0.0, 0.37}) {
    Eigen::VectorXd x(300);
    for (int i = 0; i < 300; ++i) x[i] = 2.5 + slope * i;
    const Decomposition d = Decompose(x, Options(GetParam()), kOneThread);
    EXPECT_EQ(d.num_imfs(), 0) << "slope " << slope;
    EXPECT_EQ(d.residue, x);
  }
}

TEST_P(Decomposer, WellSeparatedTonesLandInSeparateImfs) {
  const int n = 2048;
  Eigen::VectorXd fast(n), slow(n);
  for (int i = 0; i < n; ++i) {
    fast[i] = std::sin(2 * std::numbers::pi * i / 10.0);
    slow[i] = 2.0 * std::sin(2 * std::numbers::pi * i / 400.0);
  }
  const Eigen::VectorXd x = fast + slow;
  const Decomposition d = Decompose(x, Options(GetParam()), kOneThread);
  ASSERT_GE(d.num_imfs(), 2);
  // The IMF most correlated with each tone carries it almost entirely, and they differ.
  auto best = [&](const Eigen::VectorXd& tone, double* corr) {
    int k_best = 0;
    *corr = -1;
    for (int k = 0; k < d.num_imfs(); ++k) {
      const double c = d.imfs.col(k).dot(tone) / (d.imfs.col(k).norm() * tone.norm() + 1e-300);
      if (c > *corr) {
        *corr = c;
        k_best = k;
      }
    }
    return k_best;
  };
  double c_fast, c_slow;
  const int k_fast = best(fast, &c_fast);
  const int k_slow = best(slow, &c_slow);
  EXPECT_NE(k_fast, k_slow);
  // CEEMDAN (Torres 2011) leaves residual noise and spreads the fast tone over its first modes,
  // the defect ICEEMDAN (Colominas 2014) was designed to remove: a weaker bound for it only.
  const double bound = GetParam() == Method::kCeemdan ? 0.88 : 0.95;
  EXPECT_GT(c_fast, bound);
  EXPECT_GT(c_slow, 0.95);
}

TEST_P(Decomposer, BadInputIsRejectedWithAClearError) {
  const DecompositionOptions o = Options(GetParam());
  Eigen::VectorXd tiny(3);
  tiny << 1, 2, 1;
  EXPECT_THROW(Decompose(tiny, o, kOneThread), DataError);
  Eigen::VectorXd with_nan = Noisy(64, 5);
  with_nan[10] = std::nan("");
  try {
    Decompose(with_nan, o, kOneThread);
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("sample 11"), std::string::npos) << e.what();
  }
  // Every option is checked, also those the method does not use.
  const std::vector<std::pair<const char*, void (*)(DecompositionOptions&)>> bad_options = {
      {"rilling_threshold1", [](DecompositionOptions& b) { b.sifting.rilling_threshold1 = 2.0; }},
      {"max_imfs", [](DecompositionOptions& b) { b.max_imfs = -1; }},
      {"ensemble_size", [](DecompositionOptions& b) { b.ensemble_size = 0; }},
      {"noise_strength", [](DecompositionOptions& b) { b.noise_strength = -0.1; }},
      {"band_confidence", [](DecompositionOptions& b) { b.band_confidence = 0.5; }},
  };
  DecompositionOptions bad;
  for (const auto& [field, spoil] : bad_options) {
    bad = o;
    spoil(bad);
    EXPECT_THROW(Decompose(Noisy(64, 5), bad, kOneThread), UsageError) << field;
  }
  if (UsesNoiseEmds(GetParam())) {
    // 1e5 realisations of 1e7 samples would hold 8 TB of noise state: refused before any work.
    bad = o;
    bad.ensemble_size = 100000;
    const Eigen::VectorXd long_signal = Eigen::VectorXd::LinSpaced(10000000, 0.0, 1.0);
    try {
      Decompose(long_signal, bad, kOneThread);
      FAIL();
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("fits in half the memory"), std::string::npos)
          << e.what();
    }
  }
  if (GetParam() != Method::kEmd) {
    EXPECT_THROW(DecomposeWithNoise(Noisy(64, 5), Eigen::MatrixXd::Zero(63, 4), o, kOneThread),
                 DataError);
  } else {
    EXPECT_THROW(DecomposeWithNoise(Noisy(64, 5), Eigen::MatrixXd::Zero(64, 4), o, kOneThread),
                 UsageError);  // EMD adds no noise
  }
  EXPECT_THROW(Decompose(Noisy(64, 5), o, Threads(-1)), UsageError);
  EXPECT_THROW(Decompose(Noisy(64, 5), o, Threads(1025)), UsageError);
}

TEST_P(Decomposer, ProgressIsMonotoneAndDoesNotChangeTheResult) {
  if (GetParam() == Method::kEmd) GTEST_SKIP() << "plain EMD reports no progress";
  const Eigen::VectorXd x = Noisy(512, 7);
  const DecompositionOptions o = Options(GetParam());
  DecompositionContext context = Threads(2);
  const Decomposition plain = Decompose(x, o, context);
  std::vector<double> seen;
  context.execution.progress = [&seen, &o](double f, std::string_view step) {
    EXPECT_EQ(step, ToString(o.method));
    seen.push_back(f);
  };
  const Decomposition with_progress = Decompose(x, o, context);
  EXPECT_EQ(plain.imfs, with_progress.imfs);
  ASSERT_GE(seen.size(), static_cast<size_t>(o.ensemble_size));
  EXPECT_GT(seen.front(), 0.0);
  EXPECT_LE(seen.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
}

// The observer sees exactly the plain-EMD IMFs of each realisation's white noise (CEEMDAN family),
// in mode order, and watching does not change the result.
TEST_P(Decomposer, NoiseImfObserverSeesTheNoiseEmdAndDoesNotChangeTheResult) {
  const Eigen::VectorXd x = Noisy(512, 8);
  const DecompositionOptions o = Options(GetParam());
  DecompositionContext context = Threads(2);
  const Decomposition plain = Decompose(x, o, context);
  std::vector<std::vector<Eigen::VectorXd>> seen(static_cast<size_t>(o.ensemble_size));
  std::vector<int> out_of_order(static_cast<size_t>(o.ensemble_size), 0);
  context.noise_imf_observer = [&](int i, int mode, const double* imf) {
    auto& modes = seen[static_cast<size_t>(i)];
    out_of_order[static_cast<size_t>(i)] += static_cast<int>(modes.size()) != mode - 1;
    modes.push_back(Eigen::Map<const Eigen::VectorXd>(imf, x.size()));
  };
  const Decomposition watched = Decompose(x, o, context);
  EXPECT_EQ(plain.imfs, watched.imfs);
  EXPECT_EQ(plain.residue, watched.residue);
  const bool family = UsesNoiseEmds(GetParam());
  for (int i = 0; i < o.ensemble_size; ++i) {
    const auto& modes = seen[static_cast<size_t>(i)];
    if (!family) {
      EXPECT_TRUE(modes.empty()) << i;
      continue;
    }
    EXPECT_EQ(out_of_order[static_cast<size_t>(i)], 0) << i;
    ASSERT_GE(modes.size(), 3u) << i;
    Eigen::VectorXd w(x.size());
    Rng(o.seed, static_cast<std::uint64_t>(i)).FillNormal(w);
    const Decomposition noise = Emd(w, o.sifting);
    ASSERT_LE(static_cast<int>(modes.size()), noise.num_imfs()) << i;
    for (size_t k = 0; k < modes.size(); ++k) {
      EXPECT_EQ(modes[k], noise.imfs.col(static_cast<Eigen::Index>(k))) << i << " mode " << k + 1;
    }
  }
}

// Precomputed white-noise EMDs (the causal protocol's shared set) change nothing: the same bits,
// the same report and the same observer calls as each decomposition computing its own; other
// methods refuse them.
TEST_P(Decomposer, SharedNoiseEmdsGiveTheSameBits) {
  const Eigen::VectorXd x = Noisy(700, 8);
  DecompositionOptions o = Options(GetParam());
  const bool family = UsesNoiseEmds(GetParam());
  DecompositionContext context = Threads(2);
  auto shared = std::make_shared<const NoiseEmds>(x.size(), o, context.execution);
  if (!family) {
    context.noise_emds = shared;
    EXPECT_THROW(Decompose(x, o, context), UsageError);
    return;
  }
  std::vector<BeemdanBound> bounds = {BeemdanBound::kEnergyBand};
  if (GetParam() == Method::kBeemdan) {
    bounds = {BeemdanBound::kEnsembleBand, BeemdanBound::kEnergyBand, BeemdanBound::kFixedStages,
              BeemdanBound::kFull};
  }
  for (BeemdanBound bound : bounds) {
    o.beemdan_bound = bound;
    o.noise_stages = 2;
    using Calls = std::vector<std::tuple<int, int, double>>;  // realisation, mode, middle sample
    std::mutex mutex;  // calls for different realisations may come concurrently
    auto watch = [&](Calls& calls) {
      return [&calls, &mutex, n = x.size()](int i, int mode, const double* imf) {
        std::lock_guard<std::mutex> lock(mutex);
        calls.emplace_back(i, mode, imf[n / 2]);
      };
    };
    Calls own_calls, shared_calls;
    context.noise_emds = nullptr;
    context.noise_imf_observer = watch(own_calls);
    const Decomposition own = Decompose(x, o, context);
    context.noise_emds = shared;
    context.noise_imf_observer = watch(shared_calls);
    const Decomposition reused = Decompose(x, o, context);
    const std::string label(ToString(bound));
    EXPECT_EQ(own.imfs, reused.imfs) << label;
    EXPECT_EQ(own.residue, reused.residue) << label;
    EXPECT_EQ(own.report.Summary(), reused.report.Summary()) << label;
    std::sort(own_calls.begin(), own_calls.end());
    std::sort(shared_calls.begin(), shared_calls.end());
    EXPECT_EQ(own_calls, shared_calls) << label;
  }
}

TEST(NoiseEmds, AreEachRealisationsEmdWhateverTheThreadCount) {
  DecompositionOptions o = Options(Method::kIceemdan);
  o.ensemble_size = 5;
  const NoiseEmds one(300, o, {.threads = 1});
  const NoiseEmds two(300, o, {.threads = 2});
  ASSERT_EQ(one.ensemble_size(), 5);
  for (int i = 0; i < 5; ++i) {
    const NoiseEmds::Realisation& r = one.realisation(i);
    Eigen::VectorXd w(300);
    Rng(o.seed, static_cast<std::uint64_t>(i)).FillNormal(w);
    EXPECT_EQ(r.white, w) << i;
    const Decomposition emd = Emd(w, o.sifting);
    ASSERT_EQ(r.imfs, emd.num_imfs()) << i;
    ASSERT_EQ(r.rows.size(), static_cast<size_t>(emd.num_imfs() + 1)) << i;
    for (int k = 0; k < r.imfs; ++k) EXPECT_EQ(r.rows[static_cast<size_t>(k)], emd.imfs.col(k));
    EXPECT_EQ(r.rows.back(), emd.residue) << i;
    EXPECT_EQ(two.realisation(i).rows, r.rows) << i;
  }
}

TEST(NoiseEmds, AMismatchIsRefused) {
  const Eigen::VectorXd x = Noisy(400, 3);
  DecompositionOptions o = Options(Method::kBeemdan);
  auto shared = std::make_shared<const NoiseEmds>(x.size(), o);
  DecompositionContext with_shared;
  with_shared.noise_emds = shared;
  auto refused = [&](const DecompositionOptions& changed, const Eigen::VectorXd& signal) {
    EXPECT_THROW(Decompose(signal, changed, with_shared), UsageError);
  };
  refused(o, x.head(399));
  DecompositionOptions c = o;
  c.seed = 8;
  refused(c, x);
  c = o;
  c.ensemble_size = 15;
  refused(c, x);
  c = o;
  c.sifting.stop_rule = StopRule::kSNumber;
  refused(c, x);
  // Any valid noise (it varies: a constant column is refused as data first).
  const Eigen::MatrixXd ramps =
      Eigen::VectorXd::LinSpaced(400, -1.0, 1.0).replicate(1, 16).array().sin().matrix();
  EXPECT_THROW(DecomposeWithNoise(x, ramps, o, with_shared), UsageError) << "supplied noise";
  EXPECT_NO_THROW(Decompose(x, o, with_shared));
  EXPECT_THROW(NoiseEmds(3, o), DataError);
  EXPECT_THROW(NoiseEmds(400, o, {.threads = -1}), UsageError);
  c = o;
  c.ensemble_size = 0;
  EXPECT_THROW(NoiseEmds(400, c), UsageError);
}

TEST_P(Decomposer, EveryStopRuleTerminatesWithinItsCap) {
  for (StopRule rule :
       {StopRule::kRilling, StopRule::kSNumber, StopRule::kFixed, StopRule::kCauchySd}) {
    DecompositionOptions o = Options(GetParam());
    o.sifting.stop_rule = rule;
    const Decomposition d = Decompose(Noisy(600, 6), o, kOneThread);
    ASSERT_GE(d.num_imfs(), 1) << ToString(rule);
    for (int s : d.report.sifts_per_imf) EXPECT_LE(s, o.sifting.EffectiveMaxSifts());
    if (rule == StopRule::kFixed && GetParam() == Method::kEmd) {
      EXPECT_EQ(d.report.sifts_per_imf.front(), 10);
    }
  }
}

}  // namespace

// Readable test names and failure messages.
void PrintTo(Method method, std::ostream* os) { *os << ToString(method); }

namespace {

INSTANTIATE_TEST_SUITE_P(AllMethods, Decomposer,
                         ::testing::Values(Method::kEmd, Method::kEemd, Method::kCeemdan,
                                           Method::kIceemdan, Method::kBeemdan),
                         [](const auto& info) { return std::string(ToString(info.param)); });

}  // namespace
}  // namespace gyrodrift::decomposition
