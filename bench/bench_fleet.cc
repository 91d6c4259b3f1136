// Fleet calibration cost (issue 13). BM_CalibrateUnit: one three-axis unit through the whole
// per-unit pipeline of `gyrodrift calibrate` (fleet::CalibrateUnit: read the logs, identify the
// thermal model of each axis on an 8-h 1 Hz calibration log, compensate an 8-h verification log,
// four Allan analyses with their IEEE 952 fits per axis, the unit's HTML page); the simulated
// gyros of the three axes differ by seed. A fleet's wall time is about units x this / cores
// (units run in parallel, each single-threaded). Smoke mode (CTest): 30-minute logs.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "bench_util.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/simulation/fog_simulator.h"

namespace {

namespace fleet = gyrodrift::fleet;
namespace html = gyrodrift::html;
namespace io = gyrodrift::io;
namespace simulation = gyrodrift::simulation;

// A three-axis log of one programme: gyro_x/y/z from simulator seeds, one temperature per axis.
void WriteLog(const std::string& path, const char* programme, std::uint64_t seed) {
  std::vector<io::CsvColumn> columns;
  for (int axis = 0; axis < 3; ++axis) {
    simulation::SimulationOptions o;
    o.seed = seed + static_cast<std::uint64_t>(axis);
    o.duration_s = gyrodrift::bench::SmokeMode() ? 1800.0 : 28800.0;
    const simulation::SimulationResult r = simulation::Simulate(
        simulation::BuiltinProgramme(programme),
        simulation::PresetParameters(simulation::Preset::kNavigation), o);
    const std::string a(1, static_cast<char>('x' + axis));
    if (axis == 0) columns.push_back({"time_s", r.time_s});
    columns.push_back({"gyro_" + a, r.rate_dph});
    columns.push_back({"temp_" + a, r.temperature_c});
    columns.push_back({"drift_" + a, r.drift_dph});
  }
  io::WriteCsv(path, columns);
}

void BM_CalibrateUnit(benchmark::State& state) {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() / "gyrodrift_bench_fleet";
    std::filesystem::create_directories(d);
    WriteLog((d / "cal.csv").string(), "chamber", 1);
    WriteLog((d / "ver.csv").string(), "chamber-b", 11);
    return d.string();
  }();
  fleet::Manifest m;
  m.path = dir + "/fleet.toml";
  for (const char* a : {"x", "y", "z"}) {
    m.axes.push_back({std::string("gyro_") + a, {std::string("temp_") + a},
                      std::string("drift_") + a, 0});
  }
  m.units.push_back({"SN-1", {dir + "/cal.csv"}, {dir + "/ver.csv"}, 0});
  const html::DygraphsAssets assets = html::LoadDygraphs();
  for (auto _ : state) {
    const fleet::UnitOutputs out = fleet::CalibrateUnit(m, m.units[0], assets);
    if (!out.result.error.empty()) state.SkipWithError(out.result.error.c_str());
    benchmark::DoNotOptimize(out.files.data());
  }
  state.counters["axes"] = 3;
}
BENCHMARK(BM_CalibrateUnit)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
