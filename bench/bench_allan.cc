// Allan-variance benchmarks: overlapping ADEV of a white-noise rate record, octave grid and every
// averaging factor, with noise identification, EDF and confidence intervals (the defaults of
// allan::Compute), on all cores and on one, and the octave deviation alone on one; and the
// IEEE 952 noise fit of an octave curve.
//   build-*/bench/bench_allan --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <map>

#include "bench_util.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/random.h"

namespace {

using gyrodrift::allan::AllanOptions;
using gyrodrift::allan::Compute;
using gyrodrift::allan::Deviation;
using gyrodrift::allan::TauGrid;

const Eigen::VectorXd& Record(Eigen::Index n) {
  static std::map<Eigen::Index, Eigen::VectorXd> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    Eigen::VectorXd v(n);
    gyrodrift::Rng(42, 0).FillNormal(v);
    it = cache.emplace(n, std::move(v)).first;
  }
  return it->second;
}

void Run(benchmark::State& state, TauGrid grid, Deviation dev, int threads, bool intervals) {
  const Eigen::VectorXd& y = Record(state.range(0));
  AllanOptions o{
      .rate_hz = 100.0, .deviation = dev, .grid = grid, .confidence_intervals = intervals};
  std::size_t taus = 0;
  for (auto _ : state) {
    const auto r = Compute(y, o, {.threads = threads});
    taus = r.points.size();
    benchmark::DoNotOptimize(r.points.data());
  }
  state.counters["taus"] = static_cast<double>(taus);
  // Time per sample (wall clock): flat from 1e6 to 1e8 samples if the cost is linear in N; the
  // octave grid's log2(N) taus alone make it grow by 26/19 over that range.
  state.counters["ns/sample"] = benchmark::Counter(
      static_cast<double>(state.range(0)) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_OadevOctave(benchmark::State& s) { Run(s, TauGrid::kOctave, Deviation::kOadev, 0, true); }
void BM_OadevOctave1Thread(benchmark::State& s) {
  Run(s, TauGrid::kOctave, Deviation::kOadev, 1, true);
}
// The deviation alone (no noise identification, EDF or intervals): what allantools' oadev
// computes, for the side-by-side table of docs/performance.md.
void BM_OadevOctaveNoIntervals1Thread(benchmark::State& s) {
  Run(s, TauGrid::kOctave, Deviation::kOadev, 1, false);
}
void BM_OadevAll(benchmark::State& s) { Run(s, TauGrid::kAll, Deviation::kOadev, 0, true); }
void BM_OadevAllNoIntervals(benchmark::State& s) {
  Run(s, TauGrid::kAll, Deviation::kOadev, 0, false);
}
void BM_MdevOctave(benchmark::State& s) { Run(s, TauGrid::kOctave, Deviation::kMdev, 0, true); }
void BM_TotdevOctave(benchmark::State& s) { Run(s, TauGrid::kOctave, Deviation::kTotdev, 0, true); }

// IEEE 952 noise fit (with the correlation of the points) of the octave OADEV curve of a record:
// the cost does not depend on the record length, only on the number of fitted points.
void BM_NoiseFit(benchmark::State& state) {
  const auto curve = Compute(Record(state.range(0)), AllanOptions{.rate_hz = 100.0});
  for (auto _ : state) {
    const auto terms = gyrodrift::allan::IdentifyNoise(curve);
    benchmark::DoNotOptimize(terms.n_dpsh.value);
  }
  state.counters["points"] = static_cast<double>(curve.points.size());
}

void Register() {
  const bool smoke = gyrodrift::bench::SmokeMode();
  // The scaling table of docs/performance.md: 1e5 to 1e8 samples (1e8: 1.6 GB for the record
  // and its phase).
  const std::vector<std::int64_t> scaling =
      smoke ? std::vector<std::int64_t>{10000}
            : std::vector<std::int64_t>{100000, 1000000, 10000000, 100000000};
  for (auto n : scaling) {
    benchmark::RegisterBenchmark("BM_OadevOctave", BM_OadevOctave)
        ->Arg(n)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark("BM_OadevOctave1Thread", BM_OadevOctave1Thread)
        ->Arg(n)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark("BM_OadevOctaveNoIntervals1Thread",
                                 BM_OadevOctaveNoIntervals1Thread)
        ->Arg(n)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  const std::vector<std::int64_t> octave =
      smoke ? std::vector<std::int64_t>{10000} : std::vector<std::int64_t>{1000000, 10000000};
  for (auto n : octave) {
    benchmark::RegisterBenchmark("BM_MdevOctave", BM_MdevOctave)
        ->Arg(n)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("BM_TotdevOctave", BM_TotdevOctave)
        ->Arg(n)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("BM_NoiseFit", BM_NoiseFit)
      ->Arg(smoke ? 10000 : 1000000)
      ->Unit(benchmark::kMillisecond);
  const std::int64_t all_n = smoke ? 2000 : 1000000;
  benchmark::RegisterBenchmark("BM_OadevAll", BM_OadevAll)
      ->Arg(all_n)
      ->Unit(benchmark::kSecond)
      ->Iterations(1);
  benchmark::RegisterBenchmark("BM_OadevAllNoIntervals", BM_OadevAllNoIntervals)
      ->Arg(all_n)
      ->Unit(benchmark::kSecond)
      ->Iterations(1);
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
