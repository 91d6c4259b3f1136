// Cost of the drift model on the issue-4 record: MS-ELM fitted on an 8-hour 1 Hz simulator log
// (navigation preset, builtin programme "chamber", seed 1; 28,800 samples; BEEMDAN defaults:
// 100 realisations, ensemble-band bound, and every stage noise-assisted for comparison; 1 and 2
// threads), in both modes, and the causal evaluation of
// that record (fit on the first 70 %, then the BEEMDANs of the causal windows with their
// mirrored tails per test sample, 8,640 origins, with CausalOptions' default windows). Targets: fit
// < 1 s on 2 cores (issue 24), causal evaluation < 2 min. Wall time is the figure (UseRealTime);
// `process_cpu_s` is the CPU time of every thread of the process per iteration (Google Benchmark's
// CPU column counts the main thread only). BM_ThermalFit: the compensate-mode default (method
// thermal: identification of the thermal model, every subset of up to two thermal states scored by
// blocked cross-validation) on a 16-hour 1 Hz record (57,600 samples; the chamber programme, held
// after its end). Target: < 10 s on 2 cores. Smoke mode (CTest): a 30-minute record and 10
// realisations.
#include <benchmark/benchmark.h>

#include <ctime>
#include <string>

#include "bench_util.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/simulation/fog_simulator.h"

namespace {

namespace drift = gyrodrift::drift;
namespace simulation = gyrodrift::simulation;

double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

const simulation::SimulationResult& Record() {
  static const simulation::SimulationResult record = [] {
    simulation::SimulationOptions o;
    o.seed = 1;
    if (gyrodrift::bench::SmokeMode()) o.duration_s = 1800.0;
    return simulation::Simulate(simulation::BuiltinProgramme("chamber"),
                                simulation::PresetParameters(simulation::Preset::kNavigation), o);
  }();
  return record;
}

drift::DriftOptions Options(drift::Mode mode) {
  drift::DriftOptions o;
  o.mode = mode;
  if (gyrodrift::bench::SmokeMode()) o.decomposition.ensemble_size = 10;
  return o;
}

// Args: mode, threads, BEEMDAN bound (decomposition::BeemdanBound: the default ensemble band, or
// kFull, every stage noise-assisted as ICEEMDAN, for the time the bound saves), and the
// ensemble size, also the grouping's white-noise realisations (smoke mode: 10 and the default).
void BM_MsElmFit(benchmark::State& state) {
  const auto& r = Record();
  drift::DriftOptions o = Options(static_cast<drift::Mode>(state.range(0)));
  o.decomposition.beemdan_bound =
      static_cast<gyrodrift::decomposition::BeemdanBound>(state.range(2));
  if (!gyrodrift::bench::SmokeMode()) {
    o.decomposition.ensemble_size = static_cast<int>(state.range(3));
    o.selection.monte_carlo.realisations = static_cast<int>(state.range(3));
  }
  const gyrodrift::Execution execution{.threads = static_cast<int>(state.range(1))};
  double cpu = 0.0;
  for (auto _ : state) {
    const double start = ProcessCpuSeconds();
    const drift::DriftModel model =
        drift::FitDriftModel(r.rate_dph, r.temperature_c, o, {}, execution);
    cpu += ProcessCpuSeconds() - start;
    benchmark::DoNotOptimize(model.sub_models.data());
  }
  state.counters["process_cpu_s"] =
      benchmark::Counter(cpu / static_cast<double>(state.iterations()));
  state.counters["samples"] = static_cast<double>(r.rate_dph.size());
  state.SetLabel(std::string(drift::ToString(o.mode)) + ", bound " +
                 std::string(gyrodrift::decomposition::ToString(o.decomposition.beemdan_bound)) +
                 ", I = R = " + std::to_string(o.decomposition.ensemble_size));
}

void BM_ThermalFit(benchmark::State& state) {
  static const simulation::SimulationResult record = [] {
    simulation::SimulationOptions o;
    o.seed = 1;
    o.duration_s = gyrodrift::bench::SmokeMode() ? 1800.0 : 57600.0;
    return simulation::Simulate(simulation::BuiltinProgramme("chamber"),
                                simulation::PresetParameters(simulation::Preset::kNavigation), o);
  }();
  drift::DriftOptions o = Options(drift::Mode::kCompensate);
  o.method = drift::Method::kThermal;
  double cpu = 0.0;
  for (auto _ : state) {
    const double start = ProcessCpuSeconds();
    const drift::DriftModel model =
        drift::FitDriftModel(record.rate_dph, record.temperature_c, o, {}, {.threads = 2});
    cpu += ProcessCpuSeconds() - start;
    benchmark::DoNotOptimize(model.sub_models.data());
  }
  state.counters["process_cpu_s"] =
      benchmark::Counter(cpu / static_cast<double>(state.iterations()));
  state.counters["samples"] = static_cast<double>(record.rate_dph.size());
}

void BM_CausalEvaluation(benchmark::State& state) {
  const auto& r = Record();
  const drift::DriftOptions o = Options(drift::Mode::kPredict);
  const gyrodrift::Execution execution{.threads = static_cast<int>(state.range(0))};
  drift::EvaluationOptions eo;
  eo.methods = {drift::Method::kMsElm};
  eo.protocols = {drift::Protocol::kCausal};
  if (gyrodrift::bench::SmokeMode()) eo.causal.window = 64;
  double cpu = 0.0;
  double rmse = 0.0;
  for (auto _ : state) {
    const double start = ProcessCpuSeconds();
    const drift::EvaluationResult result =
        drift::Evaluate(r.rate_dph, Eigen::VectorXd(), r.drift_dph, o, eo, execution);
    cpu += ProcessCpuSeconds() - start;
    rmse = result.rows.front().rmse;
  }
  state.counters["process_cpu_s"] =
      benchmark::Counter(cpu / static_cast<double>(state.iterations()));
  state.counters["rmse_dph"] = rmse;
}

// Predict mode (the paper's task) at 1 and 2 threads, with the default bound and forced to every
// stage (ICEEMDAN: what the bound saves); compensate mode at 2 threads; and predict mode with 20
// realisations for the decomposition and the grouping's level (the fit's cost is proportional
// to them: docs/performance.md section 4).
BENCHMARK(BM_MsElmFit)
    ->ArgsProduct({{static_cast<int>(drift::Mode::kPredict)},
                   {1, 2},
                   {static_cast<int>(gyrodrift::decomposition::BeemdanBound::kEnsembleBand),
                    static_cast<int>(gyrodrift::decomposition::BeemdanBound::kFull)},
                   {100}})
    ->Args({static_cast<int>(drift::Mode::kCompensate), 2,
            static_cast<int>(gyrodrift::decomposition::BeemdanBound::kEnsembleBand), 100})
    ->Args({static_cast<int>(drift::Mode::kPredict), 2,
            static_cast<int>(gyrodrift::decomposition::BeemdanBound::kEnsembleBand), 20})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

BENCHMARK(BM_ThermalFit)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_CausalEvaluation)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
