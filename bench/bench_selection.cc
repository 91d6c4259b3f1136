// Mode-selection speed. Targets: the binned-FFT KDE of a 1e5-sample IMF in milliseconds (the
// direct O(n * grid) sum shown beside it), the whole PDF-similarity selection of a typical
// 28,800-sample EMD (8 h at 1 Hz) with the white-noise level already cached, and the one-off
// Monte-Carlo level (plain EMD of white noise, dominated by the EMDs; reported per realisation).
// Inputs: seeded white noise plus a slow sine and a trend, the mix a gyro log has.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "bench_util.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/selection/selection.h"

namespace {

namespace sel = gyrodrift::selection;

Eigen::VectorXd Signal(Eigen::Index n) {
  gyrodrift::Rng rng(2016, 0);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(n);
    x[i] = rng.Normal() + 4.0 * std::sin(2 * std::numbers::pi * 4 * t) + 6.0 * t;
  }
  return x;
}

// Silverman bandwidth + grid + linear binning + FFT convolution, as SelectModes does per IMF.
void Kde(benchmark::State& state, sel::KdeMethod method) {
  Eigen::VectorXd x(state.range(0));
  gyrodrift::Rng(1, 0).FillNormal(x);
  const sel::KdeOptions options;
  sel::KdeWorkspace workspace;
  Eigen::VectorXd density;
  int points = 0;
  for (auto _ : state) {
    const double h = sel::SilvermanBandwidth(x, &workspace);
    const sel::Grid grid = sel::MakeGrid(x.minCoeff() - 5 * h, x.maxCoeff() + 5 * h, h, options);
    density.resize(grid.points);
    sel::EstimateDensity(x, 0.0, 1.0, h, grid, method, &workspace, density);
    benchmark::DoNotOptimize(density.data());
    points = grid.points;
  }
  state.counters["grid"] = points;
}

void BM_KdeBinnedFft(benchmark::State& state) { Kde(state, sel::KdeMethod::kBinnedFft); }
void BM_KdeDirect(benchmark::State& state) { Kde(state, sel::KdeMethod::kDirect); }

void BM_SelectModesCachedLevel(benchmark::State& state) {
  const Eigen::VectorXd x = Signal(state.range(0));
  const auto d = gyrodrift::decomposition::Emd(x);
  sel::SelectionOptions options;
  const gyrodrift::Execution execution{.threads = static_cast<int>(state.range(1))};
  options.monte_carlo.realisations = 20;  // only primes the cache; not timed
  sel::SelectModes(x, d, options, execution);
  int grid = 0;
  for (auto _ : state) {
    const auto r = sel::SelectModes(x, d, options, execution);
    benchmark::DoNotOptimize(r.groups.data());
    grid = r.grid_points;
  }
  state.counters["imfs"] = d.num_imfs();
  state.counters["grid"] = grid;
}

void BM_NoiseLevelMonteCarlo(benchmark::State& state) {
  sel::MonteCarloOptions mc;
  mc.realisations = 20;
  const gyrodrift::Execution execution{.threads = static_cast<int>(state.range(1))};
  for (auto _ : state) {
    const auto level = sel::ComputeNoiseLevel(static_cast<int>(state.range(0)), mc, {},
                                              sel::PdfDistance::kL2, execution);
    benchmark::DoNotOptimize(level.level.data());
  }
  state.counters["realisations"] = mc.realisations;
}

void Register() {
  const bool smoke = gyrodrift::bench::SmokeMode();
  auto* kde = benchmark::RegisterBenchmark("BM_KdeBinnedFft", BM_KdeBinnedFft);
  kde->Unit(benchmark::kMillisecond)->Arg(smoke ? 1000 : 100000);
  if (!smoke) kde->Arg(28800)->Arg(1000000);
  benchmark::RegisterBenchmark("BM_KdeDirect", BM_KdeDirect)
      ->Unit(benchmark::kMillisecond)
      ->Arg(smoke ? 1000 : 100000);
  auto* select =
      benchmark::RegisterBenchmark("BM_SelectModesCachedLevel", BM_SelectModesCachedLevel);
  select->Unit(benchmark::kMillisecond);
  if (smoke) {
    select->Args({1024, 1});
  } else {
    select->Args({28800, 1})->Args({28800, 2});
  }
  auto* mc = benchmark::RegisterBenchmark("BM_NoiseLevelMonteCarlo", BM_NoiseLevelMonteCarlo);
  mc->Unit(benchmark::kSecond)->Iterations(1);
  if (smoke) {
    mc->Args({512, 1});
  } else {
    mc->Args({28800, 1})->Args({28800, 2});
  }
}

}  // namespace

int main(int argc, char** argv) {
  Register();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
