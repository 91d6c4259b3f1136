// ELM speed against hpelm (Akusok et al. 2015), measured on this 2-core machine on 70,000 rows
// of 16 lags: 0.77 s to fit 200 sigmoid units, 19.5 s with leave-one-out selection, 568 s with
// leave-one-out over 1000 units. Targets (issue 4): fit 200 units < 0.1 s; leave-one-out
// selection of L among candidates up to 1000 (and of C) < 10 s. Measured figures, with the
// command and the load average of each run: docs/elm.md, "Speed".
// Input: a drift-like series (random walk + two slow tones + white noise), seeded; inputs are
// its 16 previous samples, the target the next one. The row kernels run with AVX2 + FMA when
// the CPU has them (src/elm/elm_kernels.h); the `kernels` label says which ran.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <string>

#include "bench_util.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/elm/elm.h"

namespace {

using gyrodrift::elm::ElmOptions;
using gyrodrift::elm::Selection;
using gyrodrift::elm::Solver;

constexpr int kLags = 16;

struct LagData {
  Eigen::MatrixXd x;
  Eigen::MatrixXd t;
};

const LagData& Lags(Eigen::Index rows) {
  static LagData data;
  if (data.x.rows() == rows) return data;
  gyrodrift::Rng rng(2016, 0);
  Eigen::VectorXd s(rows + kLags);
  double walk = 0.0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    walk += 0.01 * rng.Normal();
    const double t = static_cast<double>(i);
    s[i] = walk + std::sin(2 * std::numbers::pi * t / 3600.0) +
           0.3 * std::sin(2 * std::numbers::pi * t / 600.0) + 0.05 * rng.Normal();
  }
  data.x.resize(rows, kLags);
  data.t.resize(rows, 1);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (int k = 0; k < kLags; ++k) data.x(i, k) = s[i + k];
    data.t(i, 0) = s[i + kLags];
  }
  return data;
}

Eigen::Index Rows() { return gyrodrift::bench::SmokeMode() ? 2000 : 70000; }

void Run(benchmark::State& state, ElmOptions o) {
  const LagData& d = Lags(Rows());
  o.hidden_units = static_cast<int>(state.range(0));
  const gyrodrift::Execution execution{.threads = static_cast<int>(state.range(1))};
  gyrodrift::elm::ElmFit fit;
  for (auto _ : state) {
    fit = gyrodrift::elm::Fit(d.x, d.t, o, execution);
    benchmark::DoNotOptimize(fit.model.output_weights.data());
  }
  state.counters["rows"] = static_cast<double>(d.x.rows());
  state.counters["L"] = fit.report.hidden_units;
  state.counters["C"] = fit.report.ridge_c;
  state.counters["train_rmse"] = fit.report.train_rmse;
  if (o.selection == Selection::kAuto) state.counters["loo_rmse"] = fit.report.loo_rmse;
  state.SetLabel(std::string(gyrodrift::elm::KernelName()));
}

void BM_ElmFitCholesky(benchmark::State& state) { Run(state, {}); }
void BM_ElmFitQr(benchmark::State& state) { Run(state, {.solver = Solver::kQr}); }
void BM_ElmAutoLoo(benchmark::State& state) { Run(state, {.selection = Selection::kAuto}); }

void BM_ElmPredict(benchmark::State& state) {
  const LagData& d = Lags(Rows());
  const ElmOptions o{.hidden_units = static_cast<int>(state.range(0))};
  const int threads = static_cast<int>(state.range(1));
  const auto model = gyrodrift::elm::Fit(d.x, d.t, o, {.threads = threads}).model;
  for (auto _ : state) {
    Eigen::MatrixXd y = gyrodrift::elm::Predict(model, d.x, threads);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetLabel(std::string(gyrodrift::elm::KernelName()));
}

// Arguments: {hidden units (auto: the largest candidate), threads (0 = all cores)}.
void Register() {
  const bool smoke = gyrodrift::bench::SmokeMode();
  auto fit = benchmark::RegisterBenchmark("BM_ElmFitCholesky", BM_ElmFitCholesky);
  auto qr = benchmark::RegisterBenchmark("BM_ElmFitQr", BM_ElmFitQr);
  auto loo = benchmark::RegisterBenchmark("BM_ElmAutoLoo", BM_ElmAutoLoo);
  auto predict = benchmark::RegisterBenchmark("BM_ElmPredict", BM_ElmPredict);
  for (auto* b : {fit, qr, loo, predict}) b->Unit(benchmark::kMillisecond)->UseRealTime();
  if (smoke) {
    for (auto* b : {fit, qr, loo, predict}) b->Args({20, 0});
    return;
  }
  fit->Args({200, 1})->Args({200, 0})->Args({1000, 0});
  qr->Args({200, 0});
  loo->Args({200, 0})->Args({1000, 1})->Args({1000, 0})->Iterations(1);
  predict->Args({200, 0});
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
