// demo: the whole study of `gyrodrift demo` (study::RunDemo), its folder written the same.
#include <filesystem>
#include <numeric>

#include "bindings.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/study/demo.h"
#include "gyrodrift/study/study_files.h"

namespace gyrodrift::python {
namespace {

py::dict Demo(const study::DemoSettings& settings, const py::object& progress) {
  // A refusal names the keyword, as the CLI's names its flag.
  ValidateAsSettings({{"ensemble_size", "ensemble"}, {"duration_s", "duration"}},
                     [&] { ValidateAsCausalKeywords([&] { (void)settings.Options(); }); });
  LongCall call(progress);
  // The study reports (stage, fraction of it); the callable gets the fraction of the whole run,
  // each stage weighed by its measured cost.
  const std::vector<double> weights = study::DemoStageWeights(settings.input.empty());
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  const auto hook = call.Hook();
  study::StudyContext context;
  context.threads = settings.threads;
  context.progress = [&](int stage, double fraction, const std::string& what) {
    const auto s = static_cast<size_t>(stage);
    const double before = std::accumulate(weights.begin(), weights.begin() + s, 0.0);
    hook((before + fraction * weights[s]) / total, what);
  };
  study::DemoRun run;
  call.Run([&] { run = study::RunDemo(settings, context); });
  const study::StudyResult& r = run.result;
  py::list files;
  for (const study::StudyFile& f : run.files) files.append(f.name);
  py::dict tables;
  tables["predict"] = r.predict_table.Text();
  tables["compensate"] = r.compensate_table.Text();
  tables["noise_terms"] = r.terms_table.Text();
  tables["settings"] = r.settings_table.Text();
  tables["timing"] = r.timing_table.Text();
  py::dict d;
  d["output"] = settings.output;
  d["files"] = files;
  d["report"] = (std::filesystem::path(settings.output) / study::kStudyReportFile).string();
  d["simulated"] = r.simulated;
  d["compensated_by"] = r.compensated_by;
  d["best_by"] = r.best_by;
  d["tables"] = tables;
  d["seconds"] = run.seconds;
  return d;
}

}  // namespace

void BindDemo(py::module_& m) {
  using py::arg;
  const study::DemoSettings d;
  m.def(
      "demo",
      [](const std::string& output, const std::string& input, const std::string& target,
         const std::string& temperature, std::optional<double> rate_hz, const std::string& units,
         double duration, int ensemble, int realisations, int window, double mirror, int windows,
         int causal_ensemble, const std::string& methods, std::uint64_t seed, int threads,
         const std::string& gaps, const py::object& progress) {
        study::DemoSettings s{.output = output,
                              .input = input,
                              .target = target,
                              .temperature = temperature,
                              .rate_hz = rate_hz,
                              .units = units,
                              .duration_s = duration,
                              .ensemble = ensemble,
                              .realisations = realisations,
                              .causal = CausalOf(window, mirror, windows, causal_ensemble),
                              .methods = methods,
                              .seed = seed,
                              .threads = threads,
                              .log = {}};
        s.log.gaps = io::GapPolicyFromString(gaps);
        return Demo(s, progress);
      },
      arg("output") = d.output, py::kw_only(), arg("input") = d.input, arg("target") = d.target,
      arg("temperature") = d.temperature, arg("rate_hz") = py::none(), arg("units") = d.units,
      arg("duration") = d.duration_s, arg("ensemble") = d.ensemble,
      arg("realisations") = d.realisations, arg("window") = d.causal.window,
      arg("mirror") = d.causal.mirror, arg("windows") = d.causal.windows,
      arg("causal_ensemble") = d.causal.ensemble_size, arg("methods") = d.methods,
      arg("seed") = d.seed, arg("threads") = d.threads,
      arg("gaps") = std::string(io::ToString(d.log.gaps)), arg("progress") = py::none());
}

}  // namespace gyrodrift::python
