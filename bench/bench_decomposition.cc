// EMD family speed, against the libeemd 1.5.0 figures measured on this 2-core machine kind
// (S-number stop rule S = 4, at most 50 sifts): EMD 1e5 samples 0.62 s; EEMD 1e4 x 100 on 1 thread
// 3.3 s; CEEMDAN 1e4 x 100 7.4 s on 1 thread, 4.0 s on 2. Targets: 3x faster (EMD <= 0.2 s,
// EEMD <= 1.1 s, CEEMDAN <= 2.5 s on one thread, 2 threads >= 1.8x faster than 1) and BEEMDAN
// with its defaults on the same input <= 1 s.
// Input: white noise plus two tones and a trend, the mix a gyro log has (seeded, reproducible).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "bench_util.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace {

using gyrodrift::decomposition::DecompositionOptions;
using gyrodrift::decomposition::Method;
using gyrodrift::decomposition::StopRule;

Eigen::VectorXd Signal(Eigen::Index n) {
  gyrodrift::Rng rng(2016, 0);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(n);
    x[i] = rng.Normal() + 2.0 * std::sin(2 * std::numbers::pi * 40 * t) +
           3.0 * std::sin(2 * std::numbers::pi * 3 * t) + 5.0 * t;
  }
  return x;
}

DecompositionOptions LibeemdLike(Method method) {
  DecompositionOptions o;
  o.method = method;
  o.sifting.stop_rule = StopRule::kSNumber;
  o.sifting.s_number = 4;
  o.sifting.max_sifts = 50;
  o.ensemble_size = 100;
  o.noise_strength = 0.2;
  return o;
}

// Decomposes the signal of state.range(0) samples on `threads` workers.
void Run(benchmark::State& state, const DecompositionOptions& o, int threads) {
  const Eigen::VectorXd x = Signal(state.range(0));
  gyrodrift::decomposition::DecompositionContext context;
  context.execution.threads = threads;
  int imfs = 0;
  for (auto _ : state) {
    const auto d = gyrodrift::decomposition::Decompose(x, o, context);
    imfs = d.num_imfs();
    benchmark::DoNotOptimize(d.imfs.data());
  }
  state.counters["imfs"] = imfs;
  state.counters["samples"] = static_cast<double>(state.range(0));
}

int Threads(const benchmark::State& state) { return static_cast<int>(state.range(1)); }

void BM_Emd_SNumber(benchmark::State& state) { Run(state, LibeemdLike(Method::kEmd), 1); }
void BM_Emd_Rilling(benchmark::State& state) {
  DecompositionOptions o;
  o.method = Method::kEmd;
  Run(state, o, 0);
}
void BM_Eemd_SNumber(benchmark::State& state) {
  Run(state, LibeemdLike(Method::kEemd), Threads(state));
}
void BM_Ceemdan_SNumber(benchmark::State& state) {
  Run(state, LibeemdLike(Method::kCeemdan), Threads(state));
}
void BM_Iceemdan_Rilling(benchmark::State& state) {
  DecompositionOptions o;
  o.method = Method::kIceemdan;
  Run(state, o, Threads(state));
}
void BM_Beemdan_Defaults(benchmark::State& state) {
  DecompositionOptions o;  // every default: Rilling stop, I = 100, eps 0.2, 99 % band
  Run(state, o, Threads(state));
}

const bool kSmoke = gyrodrift::bench::SmokeMode();
const long kLong = kSmoke ? 2000 : 100000;
const long kShort = kSmoke ? 500 : 10000;

BENCHMARK(BM_Emd_SNumber)->Arg(kLong)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Emd_Rilling)->Arg(kLong)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Eemd_SNumber)->Args({kShort, 1})->Args({kShort, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Ceemdan_SNumber)->Args({kShort, 1})->Args({kShort, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Iceemdan_Rilling)->Args({kShort, 1})->Args({kShort, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Beemdan_Defaults)->Args({kShort, 1})->Args({kShort, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
