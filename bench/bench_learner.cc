// Fit and predict time of every learner (drift/learner.h) at the MS-ELM's input size: the 4
// previous samples of a drift-like series predict the next one (METHOD.md section 5, p = 4).
// Defaults of LearnerOptions throughout (ELM 20 sigmoid units; poly degree 2; SVR C 10,
// epsilon 0.05, gamma 1/4, at most 4000 rows; BP 4-10-1, 300 RPROP epochs), one thread.
// Input: random walk + two slow tones + white noise, seeded (as bench_elm.cc).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "bench_util.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/learner.h"

namespace {

using gyrodrift::drift::LearnerKind;
using gyrodrift::drift::LearnerOptions;

constexpr int kLags = 4;

struct LagData {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;
};

LagData MakeLags(Eigen::Index rows) {
  gyrodrift::Rng rng(2016, 0);
  Eigen::VectorXd s(rows + kLags);
  double walk = 0.0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    walk += 0.01 * rng.Normal();
    const double t = static_cast<double>(i);
    s[i] = walk + std::sin(2 * std::numbers::pi * t / 3600.0) +
           0.3 * std::sin(2 * std::numbers::pi * t / 600.0) + 0.05 * rng.Normal();
  }
  LagData data;
  data.x.resize(rows, kLags);
  data.y.resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (int k = 0; k < kLags; ++k) data.x(i, k) = s[i + k];
    data.y[i] = s[i + kLags];
  }
  return data;
}

LearnerOptions Options(int kind) {
  LearnerOptions o;
  o.kind = static_cast<LearnerKind>(kind);
  return o;
}

void BM_Fit(benchmark::State& state) {
  const LagData data = MakeLags(state.range(1));
  const LearnerOptions o = Options(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto learner = gyrodrift::drift::FitLearner(data.x, data.y, o, {.threads = 1});
    benchmark::DoNotOptimize(learner.get());
  }
  state.SetLabel(std::string(gyrodrift::drift::ToString(o.kind)));
  state.SetItemsProcessed(state.iterations() * state.range(1));
}

void BM_Predict(benchmark::State& state) {
  const LagData train = MakeLags(state.range(1));
  const LearnerOptions o = Options(static_cast<int>(state.range(0)));
  const auto learner = gyrodrift::drift::FitLearner(train.x, train.y, o);
  const LagData data = MakeLags(state.range(1));
  for (auto _ : state) {
    Eigen::VectorXd y = learner->Predict(data.x);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetLabel(std::string(gyrodrift::drift::ToString(o.kind)));
  state.SetItemsProcessed(state.iterations() * state.range(1));
}

void Sizes(benchmark::internal::Benchmark* b) {
  const bool smoke = gyrodrift::bench::SmokeMode();
  for (int kind = 0; kind < 4; ++kind) {
    if (smoke) {
      b->Args({kind, 300});
    } else {
      b->Args({kind, 2000});
      b->Args({kind, 10000});
    }
  }
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_Fit)->Apply(Sizes);
BENCHMARK(BM_Predict)->Apply(Sizes);

}  // namespace

BENCHMARK_MAIN();
