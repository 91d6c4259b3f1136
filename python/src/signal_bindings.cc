// The signal operations: decompose, allan, noise_terms, simulate and select_modes.
#include "bindings.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/drift/temperature_check.h"
#include "gyrodrift/drift/thermal_coefficients.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/fleet/manifest.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/tasks/allan_task.h"
#include "gyrodrift/tasks/decompose_task.h"
#include "gyrodrift/tasks/simulate_task.h"

namespace gyrodrift::python {
namespace {

namespace al = gyrodrift::allan;
namespace dec = gyrodrift::decomposition;
namespace sim = gyrodrift::simulation;
namespace gp = gyrodrift::python;

// ---- decompose ------------------------------------------------------------------------------

py::tuple Decompose(const Array& x_in, const tasks::DecomposeSettings& settings,
                    std::optional<Array> noise_realisations, const py::object& progress) {
  settings.Validate();
  const Eigen::VectorXd x = ToVector(x_in, "x");
  Eigen::MatrixXd supplied;  // noise_realisations, one per column
  if (noise_realisations) {
    tasks::RequireNoiseTaken(settings, "noise_realisations");
    supplied = ToMatrix(*noise_realisations, "noise_realisations");
    // Empty means "draw them" to the library: an empty array given is a mistake, not that.
    if (supplied.size() == 0) {
      throw UsageError(
          "noise_realisations: an (N, I) array with I >= 1 realisations is needed, got " +
          std::to_string(supplied.rows()) + " x " + std::to_string(supplied.cols()));
    }
  }
  LongCall call(progress);
  dec::Decomposition d;
  call.Run([&] { d = tasks::RunDecompose(x, settings, supplied, call.Hook()); });
  // The sidecar's report (`gyrodrift decompose`): the same keys and numbers.
  return py::make_tuple(ToArray(d.imfs), ToArray(d.residue),
                        ToPython(tasks::DecomposeReportRecord(d)));
}

// ---- allan ----------------------------------------------------------------------------------

py::dict Allan(const Array& x_in, const tasks::AllanSettings& settings, std::vector<bool> logged,
               const std::vector<Eigen::Index>& record_starts) {
  settings.Validate();
  Eigen::VectorXd data = ToVector(x_in, "x");
  if (!record_starts.empty()) data = tasks::JoinRecords(data, record_starts, &logged);
  tasks::AllanRun run;
  {
    py::gil_scoped_release release;
    run = tasks::RunAllan(std::move(data), logged, settings);
  }
  const al::AllanResult& r = run.curve;
  const auto n = static_cast<Eigen::Index>(r.points.size());
  Eigen::VectorXd tau(n), devs(n), lo(n), hi(n), edf(n);
  py::array_t<std::int64_t> m(n), n_terms(n), alpha(n);
  py::array_t<bool> identified(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const al::AllanPoint& p = r.points[static_cast<size_t>(i)];
    tau[i] = p.tau_s;
    devs[i] = p.dev;
    lo[i] = p.dev_lo;
    hi[i] = p.dev_hi;
    edf[i] = p.edf;
    m.mutable_at(i) = p.m;
    n_terms.mutable_at(i) = p.n_terms;
    alpha.mutable_at(i) = p.alpha;
    identified.mutable_at(i) = p.alpha_identified;
  }
  py::dict d;
  d["tau_s"] = ToArray(tau);
  d["m"] = m;
  d["dev"] = ToArray(devs);
  d["dev_lo"] = ToArray(lo);
  d["dev_hi"] = ToArray(hi);
  d["n_terms"] = n_terms;
  d["edf"] = ToArray(edf);
  d["alpha"] = alpha;
  d["alpha_identified"] = identified;
  d["dev_unit"] = run.dev_unit;
  d["samples"] = r.n_samples;
  d["summary"] = r.Summary();
  // The sidecar's record of the terms (`gyrodrift allan`): the same keys and numbers.
  d["noise_terms"] = ToPython(tasks::AllanRecord(run, settings, logged)["noise_terms"]);
  return d;
}

py::dict NoiseTerms(const Array& tau_s, const Array& adev_dph, const Array& edf, double fit_tau_min,
                    double fit_tau_max, double min_share, double significance,
                    double sample_period_s) {
  const al::NoiseFitOptions o{.tau_min_s = fit_tau_min,
                              .tau_max_s = fit_tau_max,
                              .min_share = min_share,
                              .sample_period_s = sample_period_s,
                              .significance = significance};
  o.Validate();
  const Eigen::VectorXd t = ToVector(tau_s, "tau_s"), a = ToVector(adev_dph, "adev_dph"),
                        e = ToVector(edf, "edf");
  al::NoiseTerms terms;
  {
    py::gil_scoped_release release;
    terms = al::IdentifyNoise(t, a, e, o);
  }
  return ToPython(tasks::NoiseTermsRecord(terms));
}

// ---- simulate -------------------------------------------------------------------------------

py::dict Simulate(std::optional<double> duration, const py::object& profile,
                  const std::string& preset, double rate_hz, std::uint64_t seed,
                  const std::string& winding, std::optional<double> asymmetry,
                  double input_rate_dph, bool noise) {
  sim::FogParameters params = sim::PresetParameters(sim::PresetFromString(preset));
  if (!winding.empty()) params.coil.winding = sim::WindingPatternFromString(winding);
  if (asymmetry) params.coil.winding_asymmetry = *asymmetry;
  // A refusal names the keyword (asymmetry), as the CLI's names its flag.
  ValidateAsSettings({{"coil.winding_asymmetry", "asymmetry"}}, [&] { params.Validate(); });
  // A built-in programme by name, or (time_s, temperature_c) samples of a chamber programme.
  std::optional<sim::TemperatureProgramme> programme;
  if (py::isinstance<py::str>(profile)) {
    programme = tasks::LoadProgramme(profile.cast<std::string>(), "profile");
  } else {
    std::pair<Array, Array> pair;
    try {
      pair = profile.cast<std::pair<Array, Array>>();
    } catch (const py::cast_error&) {
      throw UsageError(
          "profile: must be chamber, chamber-b, sine, a CSV file or a pair of arrays "
          "(time_s, temperature_c)");
    }
    programme = sim::TemperatureProgramme::FromSamples(
        ToVector(pair.first, "profile time_s"), ToVector(pair.second, "profile temperature_c"),
        "profile");
  }
  sim::SimulationOptions o;
  o.rate_hz = rate_hz;
  o.seed = seed;
  o.input_rate_dph = input_rate_dph;
  o.include_noise = noise;
  o.duration_s = duration ? *duration : programme->DefaultSimulationDuration();
  ValidateAsSettings({{"duration_s", "duration"}}, [&] { o.Validate(); });
  sim::SimulationResult r;
  {
    py::gil_scoped_release release;
    r = sim::Simulate(*programme, params, o);
  }
  py::dict truth;
  truth["drift_dph"] = ToArray(r.drift_dph);
  truth["shupe_dph"] = ToArray(r.shupe_dph);
  truth["stress_dph"] = ToArray(r.stress_dph);
  truth["bias_dph"] = ToArray(r.bias_dph);
  truth["noise_dph"] = ToArray(r.noise_dph);
  truth["chamber_c"] = ToArray(r.chamber_c);
  truth["case_c"] = ToArray(r.case_c);
  truth["coil_mean_c"] = ToArray(r.coil_mean_c);
  truth["coil_inner_c"] = ToArray(r.coil_inner_c);
  truth["coil_outer_c"] = ToArray(r.coil_outer_c);
  py::dict d;
  d["time_s"] = ToArray(r.time_s);
  d["rate_dph"] = ToArray(r.rate_dph);
  d["temperature_c"] = ToArray(r.temperature_c);
  d["truth"] = truth;
  d["duration_s"] = o.duration_s;
  d["seed"] = r.seed;
  d["summary"] = r.Summary();
  return d;
}

// ---- select_modes ---------------------------------------------------------------------------

// The grouping MS-ELM makes of a decomposition (docs/selection.md), with every curve it decided
// on: the selection result of the library, as a dict.
py::dict SelectModesPy(
    const Array& x_in,
    const py::array_t<double, py::array::f_style | py::array::forcecast>& imfs_in,
    const Array& residue_in, const std::string& criterion, const std::string& distance,
    int realisations, double confidence, std::uint64_t seed, double band, int threads) {
  LongCall call{py::none()};  // no progress reports: the GIL's release, Ctrl-C at the end
  selection::SelectionOptions o;
  o.criterion = selection::CriterionFromString(criterion);
  o.distance = selection::PdfDistanceFromString(distance);
  o.monte_carlo.realisations = realisations;
  o.monte_carlo.confidence = confidence;
  o.monte_carlo.seed = seed;
  o.band_confidence = band;
  ValidateAsSettings({{"monte_carlo.realisations", "realisations"},
                      {"monte_carlo.confidence", "confidence"},
                      {"band_confidence", "band"}},
                     [&] { o.Validate(); });
  const Execution execution{.threads = threads};
  execution.Validate();
  const Eigen::VectorXd x = ToVector(x_in, "x");
  if (imfs_in.ndim() != 2) throw UsageError("imfs: must be an (N, K) array, one IMF per column");
  const Eigen::MatrixXd imfs =
      Eigen::Map<const Eigen::MatrixXd>(imfs_in.data(), imfs_in.shape(0), imfs_in.shape(1));
  const Eigen::VectorXd residue = ToVector(residue_in, "residue");
  selection::SelectionResult r;
  call.Run([&] { r = selection::SelectModes(x, imfs, residue, o, execution); });
  py::list groups;
  for (const selection::ModeGroup& g : r.groups) {
    py::dict d;
    d["kind"] = std::string(selection::ToString(g.kind));
    d["imfs"] = g.imfs;
    d["has_residue"] = g.has_residue;
    d["series"] = ToArray(g.series);
    groups.append(d);
  }
  py::dict out;
  out["summary"] = r.Summary();
  out["criterion"] = std::string(selection::ToString(r.criterion));
  out["distance"] = std::string(selection::ToString(r.distance));
  out["pdf_distance"] = r.pdf_distance;
  out["self_distance"] = r.self_distance;
  out["noise_level"] = r.noise_level;
  out["log2_energy"] = r.log2_energy;
  out["energy_band_log2_upper"] = r.energy_band_log2_upper;
  out["k_star"] = r.k_star;
  out["k_noise"] = r.k_noise;
  out["mixed_end"] = r.mixed_end;
  out["energy_signal_start"] = r.energy_signal_start;
  out["groups"] = groups;
  out["grid_points"] = r.grid_points;
  out["grid_under_resolved"] = r.grid_under_resolved;
  out["noise_level_realisations"] = r.noise_level_realisations;
  out["noise_level_seed"] = r.noise_level_seed;
  out["reconstruction_error"] = r.reconstruction_error;
  out["note"] = r.note;
  return out;
}

// Half of BindSignal: the bare noise fit, the simulator and the mode selection.
void BindNoiseTermsSimulateSelect(py::module_& m) {
  using py::arg;
  const gyrodrift::allan::NoiseFitOptions nd;
  m.def("noise_terms", &gp::NoiseTerms, arg("tau_s"), arg("adev_dph"), arg("edf"), py::kw_only(),
        arg("fit_tau_min") = nd.tau_min_s, arg("fit_tau_max") = nd.tau_max_s,
        arg("min_share") = nd.min_share, arg("significance") = nd.significance,
        arg("sample_period_s") = nd.sample_period_s);
  const gyrodrift::simulation::SimulationOptions simd;
  m.def("simulate", &gp::Simulate, py::kw_only(), arg("duration") = py::none(),
        arg("profile") = "chamber", arg("preset") = "navigation", arg("rate_hz") = simd.rate_hz,
        arg("seed") = simd.seed, arg("winding") = "", arg("asymmetry") = py::none(),
        arg("input_rate_dph") = simd.input_rate_dph, arg("noise") = simd.include_noise);

  const gyrodrift::selection::SelectionOptions sd;
  m.def("select_modes", &gp::SelectModesPy, arg("x"), arg("imfs"), arg("residue"), py::kw_only(),
        arg("criterion") = std::string(gyrodrift::selection::ToString(sd.criterion)),
        arg("distance") = std::string(gyrodrift::selection::ToString(sd.distance)),
        arg("realisations") = sd.monte_carlo.realisations,
        arg("confidence") = sd.monte_carlo.confidence, arg("seed") = sd.monte_carlo.seed,
        arg("band") = sd.band_confidence, arg("threads") = 0);
}

}  // namespace

void BindSignal(py::module_& m) {
  using py::arg;
  // Defaults from default-constructed settings of the task layer, their one home
  // (python/tests/test_defaults.py checks that __init__.py and __init__.pyi show the same).
  const gyrodrift::tasks::DecomposeSettings dd;
  m.def(
      "decompose",
      [](const gp::Array& x, const std::string& method, const std::string& stop, int ensemble,
         double noise, std::uint64_t seed, int threads, int max_imfs, int max_sifts, int s_number,
         int fixed_sifts, double sd, const std::string& noise_scaling, const std::string& bound,
         double band, int noise_stages, std::optional<gp::Array> noise_realisations,
         const py::object& progress) {
        const gyrodrift::tasks::DecomposeSettings s{.method = method,
                                                    .stop = stop,
                                                    .ensemble = ensemble,
                                                    .noise = noise,
                                                    .seed = seed,
                                                    .threads = threads,
                                                    .max_imfs = max_imfs,
                                                    .max_sifts = max_sifts,
                                                    .s_number = s_number,
                                                    .fixed_sifts = fixed_sifts,
                                                    .sd = sd,
                                                    .noise_scaling = noise_scaling,
                                                    .bound = bound,
                                                    .band = band,
                                                    .noise_stages = noise_stages};
        return gp::Decompose(x, s, std::move(noise_realisations), progress);
      },
      arg("x"), py::kw_only(), arg("method") = dd.method, arg("stop") = dd.stop,
      arg("ensemble") = dd.ensemble, arg("noise") = dd.noise, arg("seed") = dd.seed,
      arg("threads") = dd.threads, arg("max_imfs") = dd.max_imfs, arg("max_sifts") = dd.max_sifts,
      arg("s_number") = dd.s_number, arg("fixed_sifts") = dd.fixed_sifts, arg("sd") = dd.sd,
      arg("noise_scaling") = dd.noise_scaling, arg("bound") = dd.bound, arg("band") = dd.band,
      arg("noise_stages") = dd.noise_stages, arg("noise_realisations") = py::none(),
      arg("progress") = py::none());
  const gyrodrift::tasks::AllanSettings allan_defaults;
  m.def(
      "allan",
      [](const gp::Array& x, double rate_hz, const std::string& type, const std::string& dev,
         const std::variant<std::string, std::vector<double>>& taus, const std::string& units,
         double confidence, int threads, double fit_tau_min, double fit_tau_max,
         const std::vector<bool>& logged, const std::vector<Eigen::Index>& record_starts) {
        gyrodrift::tasks::AllanSettings s{.rate_hz = rate_hz,
                                          .type = type,
                                          .dev = dev,
                                          .units = units,
                                          .confidence = confidence,
                                          .threads = threads,
                                          .fit_tau_min_s = fit_tau_min,
                                          .fit_tau_max_s = fit_tau_max};
        if (const auto* grid = std::get_if<std::string>(&taus)) {
          s.taus = *grid;
        } else {
          s.tau_list_s = std::get<std::vector<double>>(taus);
          if (s.tau_list_s.empty())
            throw gyrodrift::OptionError("taus", "[]", "a non-empty sequence");
        }
        return gp::Allan(x, s, logged, record_starts);
      },
      arg("x"), py::kw_only(), arg("rate_hz"), arg("type") = allan_defaults.type,
      arg("dev") = allan_defaults.dev, arg("taus") = allan_defaults.taus,
      arg("units") = allan_defaults.units, arg("confidence") = allan_defaults.confidence,
      arg("threads") = allan_defaults.threads, arg("fit_tau_min") = allan_defaults.fit_tau_min_s,
      arg("fit_tau_max") = allan_defaults.fit_tau_max_s, arg("logged") = std::vector<bool>{},
      arg("record_starts") = std::vector<Eigen::Index>{});
  BindNoiseTermsSimulateSelect(m);
}

}  // namespace gyrodrift::python
