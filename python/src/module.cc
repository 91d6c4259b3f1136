// _gyrodrift: the compiled half of the Python package `gyrodrift` (python/gyrodrift/__init__.py
// re-exports it with docstrings and examples; docs/python.md).
//
// The bindings only convert: numpy arrays to Eigen and back, keyword arguments to the library's
// option structs (named as the CLI flags name them, `-` as `_`), results to dicts. Every number
// comes from the same library calls the CLI makes, so the same inputs and options give the same
// bits (python/tests/test_cli_parity.py). Long calls run without the GIL, report progress to an
// optional callable and stop at Ctrl-C (LongCall below). Library errors become
// gyrodrift.UsageError (ValueError), DataError (ValueError) and FileError (OSError) with the
// library's one-line message.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <signal.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/common/version.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/drift/temperature_check.h"
#include "gyrodrift/drift/thermal_coefficients.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/fleet/manifest.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/io/report.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/tasks/allan_task.h"
#include "gyrodrift/tasks/decompose_task.h"

namespace py = pybind11;

namespace gyrodrift::python {
namespace {

namespace al = gyrodrift::allan;
namespace dec = gyrodrift::decomposition;
namespace sim = gyrodrift::simulation;

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A 1-D float64 copy of any array-like (lists, float32, strided views), checked under the GIL so
// the computation can run without it.
Eigen::VectorXd ToVector(const Array& a, const char* name) {
  if (a.ndim() != 1) {
    throw UsageError(std::string(name) + ": must be a 1-D array (got " + std::to_string(a.ndim()) +
                     " dimensions)");
  }
  Eigen::VectorXd v(a.shape(0));
  std::copy(a.data(), a.data() + a.shape(0), v.data());
  return v;
}

// N x C from a 1-D array (one column) or an (N, C) array.
Eigen::MatrixXd ToMatrix(const Array& a, const char* name) {
  if (a.ndim() == 1) return ToVector(a, name);
  if (a.ndim() != 2) {
    throw UsageError(std::string(name) + ": must be a 1-D or 2-D array (got " +
                     std::to_string(a.ndim()) + " dimensions)");
  }
  Eigen::MatrixXd m(a.shape(0), a.shape(1));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (py::ssize_t j = 0; j < a.shape(1); ++j) m(i, j) = r(i, j);
  return m;
}

py::array_t<double> ToArray(const Eigen::VectorXd& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

// N x K as an (N, K) array in Eigen's column-major order (one memcpy; each IMF imfs[:, k] is
// then contiguous).
py::array_t<double, py::array::f_style> ToArray(const Eigen::MatrixXd& m) {
  py::array_t<double, py::array::f_style> a({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), a.mutable_data());
  return a;
}

// ---- long calls: progress and Ctrl-C ---------------------------------------------------------

// Ctrl-C during a long call. Python runs its SIGINT handler's work on the main thread only, between
// bytecodes, which a call inside the library never reaches. So while any long call runs, SIGINT
// first goes to InterruptHandler: it counts the interrupt, which every running call's progress
// hook sees, and hands the signal on to the handler it replaced (Python's, which marks the
// KeyboardInterrupt pending as usual). The last call to end puts that handler back.
std::atomic<unsigned> g_interrupts{0};
std::mutex g_sigint_mutex;
int g_running_calls = 0;             // guarded by g_sigint_mutex
bool g_handler_installed = false;    // guarded by g_sigint_mutex
struct sigaction g_replaced_sigint;  // written before ours is installed, read by it

extern "C" void InterruptHandler(int signal, siginfo_t* info, void* context) {
  g_interrupts.fetch_add(1, std::memory_order_relaxed);
  if (g_replaced_sigint.sa_flags & SA_SIGINFO) {
    g_replaced_sigint.sa_sigaction(signal, info, context);
  } else {
    g_replaced_sigint.sa_handler(signal);
  }
}

class InterruptWatch {
 public:
  InterruptWatch() {
    std::lock_guard<std::mutex> lock(g_sigint_mutex);
    if (g_running_calls++ == 0) {
      struct sigaction current;
      ::sigaction(SIGINT, nullptr, &current);
      // Only a handler function is wrapped: under SIG_DFL or SIG_IGN (Python not handling
      // SIGINT) Ctrl-C keeps its usual effect.
      const bool function = (current.sa_flags & SA_SIGINFO) ||
                            (current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN);
      if (function) {
        g_replaced_sigint = current;
        struct sigaction ours = current;
        ours.sa_flags |= SA_SIGINFO;
        ours.sa_sigaction = InterruptHandler;
        g_handler_installed = ::sigaction(SIGINT, &ours, nullptr) == 0;
      }
    }
    start_ = g_interrupts.load(std::memory_order_relaxed);
  }
  ~InterruptWatch() {
    std::lock_guard<std::mutex> lock(g_sigint_mutex);
    if (--g_running_calls == 0 && g_handler_installed) {
      ::sigaction(SIGINT, &g_replaced_sigint, nullptr);
      g_handler_installed = false;
    }
  }
  InterruptWatch(const InterruptWatch&) = delete;
  InterruptWatch& operator=(const InterruptWatch&) = delete;

  bool Interrupted() const { return g_interrupts.load(std::memory_order_relaxed) != start_; }

 private:
  unsigned start_ = 0;
};

// A long library call: runs without the GIL on the calling thread, reports progress to the
// user's callable (with the GIL) and stops at Ctrl-C or at an exception the callable raises. The
// library reports progress through its hooks (the decomposition per realisation and stage, the
// fit per step, the causal prediction per window); once stopped, the next report throws
// Cancelled, which the library carries out of its worker threads to the call
// (ParallelOrderedReduce rethrows the first exception; nothing half-done is kept), and the call
// raises KeyboardInterrupt or the callable's exception. A call without progress reports (plain
// EMD, the paper protocol) runs to its end, then raises.
class LongCall {
 public:
  explicit LongCall(py::object progress) : progress_(std::move(progress)) {
    if (!progress_.is_none() && !PyCallable_Check(progress_.ptr())) {
      throw UsageError("progress: must be a callable taking the fraction done, or None");
    }
  }

  // The library's progress hook (Execution::progress); the step is not passed on.
  std::function<void(double, std::string_view)> Hook() {
    return [this](double fraction, std::string_view) { Report(fraction); };
  }

  // Runs work (library code only: it must not touch Python objects) to its end or its
  // cancellation. Called with the GIL held; raises what stopped it.
  template <class Work>
  void Run(Work&& work) {
    std::exception_ptr failure;
    bool interrupted = false;
    {
      InterruptWatch watch;
      watch_ = &watch;
      {
        py::gil_scoped_release release;
        try {
          work();
        } catch (...) {
          failure = std::current_exception();
        }
      }
      interrupted = watch.Interrupted();
      watch_ = nullptr;
    }
    if (error_) {  // the callable's exception, even when the work got to its end
      py::error_already_set error = std::move(*error_);
      error_.reset();
      throw error;
    }
    if (interrupted) {
      // On the main thread Python's own handler raises the pending KeyboardInterrupt here;
      // elsewhere the call raises it.
      if (PyErr_CheckSignals() == 0) PyErr_SetNone(PyExc_KeyboardInterrupt);
      throw py::error_already_set();
    }
    if (failure) std::rethrow_exception(failure);
  }

 private:
  struct Cancelled {};

  void Report(double fraction) {
    if (cancel_ || (watch_ != nullptr && watch_->Interrupted())) throw Cancelled{};
    if (progress_.is_none()) return;
    py::gil_scoped_acquire gil;
    if (cancel_) throw Cancelled{};
    try {
      progress_(fraction);
    } catch (const py::error_already_set& e) {
      error_.emplace(e);
      cancel_ = true;
      throw Cancelled{};
    }
  }

  py::object progress_;  // None or a callable taking a float
  const InterruptWatch* watch_ = nullptr;
  std::atomic<bool> cancel_{false};
  std::optional<py::error_already_set> error_;  // touched with the GIL only
};

// A record of the task layer as Python objects: the dict the sidecar's JSON object would load as,
// but with NaN kept as NaN (the JSON file writes null).
py::object ToPython(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [key, value] : j.items()) d[py::str(key)] = ToPython(value);
      return d;
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& value : j) l.append(ToPython(value));
      return l;
    }
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    default:
      return py::none();
  }
}

// ---- decompose ------------------------------------------------------------------------------

py::tuple Decompose(const Array& x_in, const tasks::DecomposeSettings& settings,
                    std::optional<Array> noise_realisations, const py::object& progress) {
  settings.Validate();
  const Eigen::VectorXd x = ToVector(x_in, "x");
  Eigen::MatrixXd supplied;  // noise_realisations, one per column
  if (noise_realisations) {
    tasks::RequireNoiseTaken(settings, "noise_realisations");
    supplied = ToMatrix(*noise_realisations, "noise_realisations");
  }
  LongCall call(progress);
  dec::Decomposition d;
  call.Run([&] { d = tasks::RunDecompose(x, settings, supplied, call.Hook()); });
  // The sidecar's report (`gyrodrift decompose`): the same keys and numbers.
  return py::make_tuple(ToArray(d.imfs), ToArray(d.residue),
                        ToPython(tasks::DecomposeReportRecord(d)));
}

// ---- allan ----------------------------------------------------------------------------------

py::dict Allan(const Array& x_in, const tasks::AllanSettings& settings,
               const std::vector<bool>& logged) {
  settings.Validate();
  const Eigen::VectorXd data = ToVector(x_in, "x");
  tasks::AllanRun run;
  {
    py::gil_scoped_release release;
    run = tasks::RunAllan(data, logged, settings);
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
  params.Validate();
  // A built-in programme by name, or (time_s, temperature_c) samples of a chamber programme.
  std::optional<sim::TemperatureProgramme> programme;
  if (py::isinstance<py::str>(profile)) {
    programme = sim::BuiltinProgramme(profile.cast<std::string>());
  } else {
    std::pair<Array, Array> pair;
    try {
      pair = profile.cast<std::pair<Array, Array>>();
    } catch (const py::cast_error&) {
      throw UsageError(
          "profile: must be chamber, chamber-b, sine or a pair of arrays "
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
  // As `gyrodrift simulate`: without a duration, the programme's own length (8 h for a sine).
  o.duration_s = duration ? *duration
                 : programme->kind() == sim::TemperatureProgramme::Kind::kSine
                     ? 8 * 3600.0
                     : programme->NominalDuration();
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

// ---- DriftModel -----------------------------------------------------------------------------

// A setting that takes "auto" or an integer (lags, hidden), as FitSettings holds it: None is
// "not given", ints and strings pass as text.
std::string AutoOrIntegerSetting(const char* name, const py::object& value) {
  if (value.is_none()) return "";
  if (py::isinstance<py::str>(value) ||
      (py::isinstance<py::int_>(value) && !py::isinstance<py::bool_>(value))) {
    return py::str(value).cast<std::string>();
  }
  throw OptionError(name, py::repr(value).cast<std::string>(), "auto or an integer");
}

std::vector<std::string> SplitColumns(const std::string& names) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = names.find(',', start);
    out.push_back(
        names.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

// The Execution of a long call's `threads` keyword (as drift::MakeExecution maps it), reporting
// to the call's progress callable; checked before any work (OptionError naming `threads`).
Execution ExecutionOf(int threads, LongCall& call) {
  const Execution execution{.threads = threads, .progress = call.Hook()};
  execution.Validate();
  return execution;
}

// One axis of a model file: the fitted model and the column names it was fitted on.
class PyDriftModel {
 public:
  PyDriftModel() = default;
  explicit PyDriftModel(io::LoadedModel loaded) : loaded_(std::move(loaded)), fitted_(true) {}

  // As `gyrodrift fit` (MakeDriftOptions above).
  void Fit(const Array& y_in, const std::optional<Array>& temperature_in,
           const drift::FitSettings& settings, const std::string& target,
           const std::optional<std::vector<std::string>>& temperature_columns,
           const std::string& source, const std::vector<Eigen::Index>& record_starts,
           const std::vector<bool>& logged, const py::object& progress) {
    LongCall call(progress);
    const drift::DriftOptions o = drift::MakeDriftOptions(settings);
    const Execution execution = ExecutionOf(settings.threads, call);

    const Eigen::VectorXd y = ToVector(y_in, "y");
    Eigen::MatrixXd temperature;
    if (temperature_in) temperature = ToMatrix(*temperature_in, "temperature");
    std::vector<std::string> names;
    if (temperature_columns) {
      names = *temperature_columns;
    } else if (temperature.cols() == 1) {
      names = {"temperature_c"};
    } else {
      for (Eigen::Index c = 0; c < temperature.cols(); ++c)
        names.push_back("temperature_c" + std::to_string(c + 1));
    }
    if (temperature_in && static_cast<Eigen::Index>(names.size()) != temperature.cols()) {
      throw UsageError("temperature_columns: " + std::to_string(names.size()) + " names for " +
                       std::to_string(temperature.cols()) + " temperature columns");
    }
    // Before the work, as `gyrodrift fit`: a temperature that does not look like degC.
    for (Eigen::Index c = 0; c < temperature.cols(); ++c) {
      const std::string w =
          drift::TemperatureWarning(temperature.col(c), names[static_cast<size_t>(c)]);
      if (!w.empty() && PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) {
        throw py::error_already_set();
      }
    }
    io::LoadedModel loaded;
    loaded.info.source = source;
    loaded.info.target_column = target;
    if (temperature_in) {
      for (size_t c = 0; c < names.size(); ++c)
        loaded.info.temperature_column += (c ? "," : "") + names[c];
    }
    call.Run([&] {
      loaded.model = drift::FitDriftModel(y, temperature, o, record_starts, execution, logged);
    });
    loaded_ = std::move(loaded);
    fitted_ = true;
  }

  const io::LoadedModel& Loaded() const {
    if (!fitted_) throw UsageError("DriftModel: not fitted (call fit() or DriftModel.load())");
    return loaded_;
  }

  void RequireMode(drift::Mode mode, const char* what) const {
    if (Loaded().model.options.mode != mode) {
      throw UsageError(std::string(what) + ": needs a model fitted with mode '" +
                       std::string(drift::ToString(mode)) + "', this one is '" +
                       std::string(drift::ToString(Loaded().model.options.mode)) + "'");
    }
  }

  py::tuple Estimate(const Array& temperature_in,
                     const std::vector<Eigen::Index>& record_starts) const {
    RequireMode(drift::Mode::kCompensate, "estimate");
    const Eigen::MatrixXd t = ToMatrix(temperature_in, "temperature");
    Eigen::MatrixXd e;
    {
      py::gil_scoped_release release;
      e = drift::EstimateDriftWithSd(Loaded().model, t, record_starts);
    }
    return py::make_tuple(ToArray(Eigen::VectorXd(e.col(0))), ToArray(Eigen::VectorXd(e.col(1))));
  }

  // y - estimate, as `gyrodrift compensate` writes it.
  py::array_t<double> Compensate(const Array& temperature_in, const Array& y_in,
                                 const std::vector<Eigen::Index>& record_starts) const {
    RequireMode(drift::Mode::kCompensate, "compensate");
    const Eigen::MatrixXd t = ToMatrix(temperature_in, "temperature");
    const Eigen::VectorXd y = ToVector(y_in, "y");
    if (y.size() != t.rows()) {
      throw DataError("compensate: y has " + std::to_string(y.size()) + " samples, temperature " +
                      std::to_string(t.rows()));
    }
    Eigen::VectorXd compensated;
    {
      py::gil_scoped_release release;
      const Eigen::MatrixXd e = drift::EstimateDriftWithSd(Loaded().model, t, record_starts);
      compensated = y - e.col(0);
    }
    return ToArray(compensated);
  }

  // The figures `gyrodrift compensate` prints and keeps in its sidecar for y compensated by this
  // model (drift::SummariseCompensation at the model's sample rate).
  py::dict CompensationSummary(const Array& temperature_in, const Array& y_in,
                               const std::vector<Eigen::Index>& record_starts) const {
    RequireMode(drift::Mode::kCompensate, "compensation_summary");
    const Eigen::MatrixXd t = ToMatrix(temperature_in, "temperature");
    const Eigen::VectorXd y = ToVector(y_in, "y");
    if (y.size() != t.rows()) {
      throw DataError("compensation_summary: y has " + std::to_string(y.size()) +
                      " samples, temperature " + std::to_string(t.rows()));
    }
    drift::CompensationSummary s;
    {
      py::gil_scoped_release release;
      const Eigen::VectorXd compensated =
          y - drift::EstimateDriftWithSd(Loaded().model, t, record_starts).col(0);
      s = drift::SummariseCompensation(y, compensated, Loaded().model.options.features.rate_hz);
    }
    auto figures = [](const drift::SignalSummary& f) {
      py::dict d;
      d["mean"] = f.mean;
      d["rms"] = f.rms;
      d["std"] = f.std;
      d["slow_variation"] = f.slow;
      return d;
    };
    py::dict d;
    d["samples"] = s.samples;
    d["before"] = figures(s.before);
    d["after"] = figures(s.after);
    d["slow_variation_block_s"] = s.block_s;
    d["slow_variation_blocks"] = s.blocks;
    d["table"] = s.Table(Loaded().info.target_column, Loaded().info.rate_unit);
    return d;
  }

  // The thermal sub-models' coefficients in physical units around `reference_temperature`, else
  // the model's reference temperature, else the calibration's means (as `gyrodrift fit` prints).
  py::list Coefficients(std::optional<double> reference_temperature) const {
    const io::LoadedModel& l = Loaded();
    const std::vector<std::string> channels = SplitColumns(l.info.temperature_column);
    const std::optional<double> reference =
        reference_temperature ? reference_temperature : l.model.options.reference_c;
    py::list out;
    for (const drift::SubModel& sub : l.model.sub_models) {
      if (!sub.thermal) continue;
      const drift::ThermalCoefficients c =
          drift::PhysicalCoefficients(*sub.thermal, reference, channels);
      py::list terms;
      for (const drift::PhysicalCoefficient& t : c.terms) {
        py::dict d;
        d["term"] = t.term;
        d["power"] = t.power;
        d["state"] = t.state;
        d["unit"] = l.info.rate_unit + t.unit;
        d["value"] = t.value;
        d["sd"] = t.sd;
        terms.append(d);
      }
      py::dict d;
      d["sub_model"] = sub.name;
      d["reference_c"] = c.reference_c;
      d["terms"] = terms;
      d["state_range_c"] = c.state_range_c;
      out.append(d);
    }
    return out;
  }

  // As `gyrodrift predict`: predictions of y[t] for t = first .. N-1, from FirstPredictable.
  py::tuple Predict(const Array& y_in, const std::optional<Array>& temperature_in, int horizon,
                    const std::string& protocol_name, int window, int threads,
                    const py::object& progress) const {
    RequireMode(drift::Mode::kPredict, "predict");
    LongCall call(progress);
    const drift::Protocol protocol = drift::ProtocolFromString(protocol_name);
    if (window < 16 || window > 1000000) {
      throw OptionError("window", std::to_string(window), "an integer in [16, 1000000]");
    }
    const drift::DriftModel& model = Loaded().model;
    const Execution execution = ExecutionOf(threads, call);  // it never changes the result
    const Eigen::VectorXd y = ToVector(y_in, "y");
    Eigen::VectorXd temperature;
    if (model.uses_temperature()) {
      if (!temperature_in) throw UsageError("predict: this model needs temperature");
      temperature = ToVector(*temperature_in, "temperature");
    }
    const Eigen::Index first = drift::FirstPredictable(model, protocol, horizon);
    if (y.size() <= first) {
      throw DataError("y has " + std::to_string(y.size()) + " samples: the model needs more than " +
                      std::to_string(first) + " (its history) to predict any");
    }
    drift::CausalOptions causal;
    causal.window = window;
    Eigen::VectorXd prediction;
    call.Run([&] {
      prediction =
          drift::PredictAhead(model, y, temperature, first, horizon, protocol, causal, execution);
    });
    return py::make_tuple(first, ToArray(prediction));
  }

  void Save(const std::string& path) const { io::WriteModelFile(path, {Loaded()}); }

  // One model file of several axes, as `gyrodrift fit --target a,b,c` writes it.
  static void SaveAxes(const std::string& path, const std::vector<const PyDriftModel*>& models) {
    if (models.empty()) throw UsageError("models: must hold at least one fitted model");
    std::vector<io::LoadedModel> axes;
    for (const PyDriftModel* m : models) axes.push_back(m->Loaded());
    io::WriteModelFile(path, axes);
  }

  static std::vector<PyDriftModel> LoadAxes(const std::string& path) {
    std::vector<PyDriftModel> out;
    for (io::LoadedModel& axis : io::ReadModelFileAxes(path)) out.emplace_back(std::move(axis));
    return out;
  }

  std::string Summary() const { return Loaded().model.Summary(); }

  py::list SubModels() const {
    const io::LoadedModel& l = Loaded();
    const std::vector<std::string> channels = SplitColumns(l.info.temperature_column);
    py::list out;
    for (const drift::SubModel& sub : l.model.sub_models) {
      py::dict d;
      d["name"] = sub.name;
      d["imfs"] = sub.imfs;
      d["has_residue"] = sub.has_residue;
      d["learner"] = sub.learner ? py::cast(sub.learner->Summary()) : py::none();
      d["mean"] = sub.mean ? py::cast(*sub.mean) : py::none();
      d["baseline"] = sub.baseline ? py::cast(sub.baseline->Summary()) : py::none();
      if (sub.thermal) {
        const drift::ThermalRegression& t = *sub.thermal;
        Eigen::VectorXd sd(t.coefficients.size());
        for (Eigen::Index k = 0; k < sd.size(); ++k) sd[k] = std::sqrt(t.covariance(k, k));
        py::dict th;
        th["summary"] = t.Summary();
        th["regressors"] = t.RegressorNames(channels);
        th["coefficients"] = ToArray(t.coefficients);
        th["sd"] = ToArray(sd);
        th["calibration"] = t.report.Summary();
        th["warnings"] = t.report.warnings;
        th["advice"] = t.report.advice;
        th["structure"] = t.report.level;  // CalibrationReport::Level: 0 the constant .. 5
        if (t.has_hysteresis()) {
          py::dict h;
          h["tau_s"] = t.states[static_cast<size_t>(t.hysteresis_state)].tau_s;
          h["width_k"] = t.hysteresis_width_k;
          h["coefficient"] = t.coefficients[t.coefficients.size() - 1];
          th["hysteresis"] = h;
        } else {
          th["hysteresis"] = py::none();
        }
        d["thermal"] = th;
      } else {
        d["thermal"] = py::none();
      }
      out.append(d);
    }
    return out;
  }

  io::LoadedModel loaded_;
  bool fitted_ = false;
};

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
  o.Validate();
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

// ---- evaluate -------------------------------------------------------------------------------

std::vector<drift::Method> MethodList(const py::object& methods, drift::Mode mode) {
  std::vector<std::string> names;
  if (py::isinstance<py::str>(methods)) {
    const std::string text = methods.cast<std::string>();
    if (text == "all") return drift::AllMethods(mode);
    names = SplitColumns(text);
  } else {
    names = methods.cast<std::vector<std::string>>();
  }
  std::vector<drift::Method> out;
  for (const std::string& name : names) {
    const drift::Method m = drift::MethodFromString(name);
    if (std::find(out.begin(), out.end(), m) != out.end()) {
      throw OptionError("methods", "'" + name + "' twice", "a list without repeats");
    }
    out.push_back(m);
  }
  if (out.empty()) throw OptionError("methods", "(empty)", "at least one method");
  return out;
}

// As `gyrodrift evaluate`: the same options (the model's as for fit), the rows as dicts.
py::dict Evaluate(const Array& y_in, const std::optional<Array>& temperature_in,
                  const std::optional<Array>& truth_in, const drift::FitSettings& settings,
                  const py::object& methods, const std::string& protocol, double split, int repeats,
                  int horizon, int window, const py::object& progress) {
  LongCall call(progress);
  const drift::DriftOptions base = drift::MakeDriftOptions(settings);
  const Execution execution = ExecutionOf(settings.threads, call);
  drift::EvaluationOptions e;
  e.split = split;
  e.repeats = repeats;
  e.methods = MethodList(methods, base.mode);
  if (protocol == "both") {
    e.protocols = {drift::Protocol::kPaper, drift::Protocol::kCausal};
  } else if (protocol == "paper" || protocol == "causal") {
    e.protocols = {drift::ProtocolFromString(protocol)};
  } else {
    throw OptionError("protocol", "'" + protocol + "'", "paper, causal or both");
  }
  e.causal.window = window;
  e.horizon = horizon;
  e.Validate();
  const Eigen::VectorXd y = ToVector(y_in, "y");
  Eigen::MatrixXd temperature;
  if (temperature_in) temperature = ToMatrix(*temperature_in, "temperature");
  Eigen::VectorXd truth;
  if (truth_in) truth = ToVector(*truth_in, "truth");
  drift::EvaluationResult result;
  call.Run([&] { result = drift::Evaluate(y, temperature, truth, base, e, execution); });

  py::list rows;
  for (const drift::EvaluationRow& r : result.rows) {
    py::dict row;
    row["method"] = std::string(drift::ToString(r.method));
    row["protocol"] = std::string(drift::ToString(r.protocol));
    row["rmse"] = r.rmse;
    row["rmse_std"] = r.rmse_std;
    row["mae"] = r.mae;
    row["max_abs"] = r.max_abs;
    row["rmse_measured"] = r.rmse_measured;
    row["slow_removed"] = r.slow_removed;
    row["train_s"] = r.train_s;
    row["predict_s"] = r.predict_s;
    row["estimate"] = ToArray(r.estimate);
    row["model_summary"] = r.model_summary;
    row["notes"] = r.notes;
    rows.append(row);
  }
  py::dict out;
  out["mode"] = std::string(drift::ToString(result.mode));
  out["first_test_sample"] = result.split_index;
  out["against_truth"] = result.against_truth;
  out["reference"] = ToArray(result.reference);
  out["rows"] = rows;
  out["training_temperature_range_c"] =
      py::make_tuple(result.training_temperature_min_c, result.training_temperature_max_c);
  out["test_outside_training_temperature_share"] = result.test_outside_training_temperature_share;
  out["table"] = result.Table();
  return out;
}

// ---- fleet ----------------------------------------------------------------------------------

py::list RowsList(const std::vector<fleet::FleetRow>& rows) {
  py::list out;
  for (const fleet::FleetRow& row : rows) {
    py::dict d;
    for (size_t c = 0; c < row.cells.size(); ++c)
      d[py::str(fleet::FleetColumns()[c])] = row.cells[c];
    out.append(d);
  }
  return out;
}

py::dict FleetDict(const fleet::FleetResult& r) {
  py::dict d;
  d["rows"] = RowsList(r.rows);
  d["units"] = r.units;
  d["calibrated"] = r.calibrated;
  d["skipped"] = r.skipped;
  d["errors"] = r.errors;
  d["failed_limits"] = r.failed_limits;
  d["seconds"] = r.seconds;
  d["unit_seconds_median"] = r.unit_seconds_median;
  d["all_pass"] = r.all_pass();
  d["summary"] = r.Summary();
  return d;
}

fleet::Manifest LoadManifest(const std::string& path) {
  fleet::Manifest m = fleet::ReadManifest(path);
  fleet::CheckLogColumns(m);  // every column of every log, before any unit is fitted
  return m;
}

py::dict Calibrate(const std::string& manifest_path, const std::string& output_dir, bool force,
                   int threads) {
  ValidateThreads(threads);
  fleet::FleetResult r;
  {
    py::gil_scoped_release release;
    const fleet::Manifest m = LoadManifest(manifest_path);
    fleet::FleetOptions o;
    o.output_dir = output_dir;
    o.force = force;
    fleet::FleetContext context;
    context.threads = threads;
    r = fleet::RunFleet(m, o, context);
  }
  return FleetDict(r);
}

// One unit (0-based index in the manifest) for gyrodrift.fleet's Dask tasks: plain lists and
// strings, so the result pickles back to the client.
py::dict CalibrateUnit(const std::string& manifest_path, int index, const std::string& output_dir,
                       bool force) {
  fleet::UnitRun run;
  {
    py::gil_scoped_release release;
    const fleet::Manifest m = LoadManifest(manifest_path);
    if (index < 0 || index >= static_cast<int>(m.units.size())) {
      throw OptionError("index", std::to_string(index),
                        "in [0, " + std::to_string(m.units.size()) + ")");
    }
    run = fleet::RunUnit(m, m.units[static_cast<size_t>(index)], output_dir, force,
                         io::LoadDygraphs());
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& row : run.rows) rows.push_back(row.cells);
  py::dict d;
  d["rows"] = rows;
  d["what"] = run.what;
  d["seconds"] = run.seconds;
  d["serial"] = run.rows.empty() ? std::string() : run.rows.front().cells[0];
  return d;
}

py::dict FinishFleet(const std::string& manifest_path, const std::string& output_dir,
                     const py::list& units, double seconds) {
  std::vector<fleet::UnitRun> runs;
  for (const py::handle& u : units) {
    fleet::UnitRun run;
    for (auto& cells : u["rows"].cast<std::vector<std::vector<std::string>>>())
      run.rows.push_back({std::move(cells)});
    run.what = u["what"].cast<std::string>();
    run.seconds = u["seconds"].cast<double>();
    runs.push_back(std::move(run));
  }
  fleet::FleetResult r;
  {
    py::gil_scoped_release release;
    const fleet::Manifest m = fleet::ReadManifest(manifest_path);
    r = fleet::FinishFleet(m, output_dir, runs, seconds, io::LoadDygraphs());
  }
  return FleetDict(r);
}

}  // namespace
}  // namespace gyrodrift::python

PYBIND11_MODULE(_gyrodrift, m) {
  namespace gp = gyrodrift::python;
  using py::arg;
  m.doc() = "Compiled core of the gyrodrift package; import gyrodrift instead.";
  m.attr("__version__") = gyrodrift::kVersion;

  // Python exception types, created here so the translator can raise them; __init__ re-exports.
  static py::exception<gyrodrift::UsageError> usage_error(m, "UsageError", PyExc_ValueError);
  static py::exception<gyrodrift::DataError> data_error(m, "DataError", PyExc_ValueError);
  static py::exception<gyrodrift::IoError> file_error(m, "FileError", PyExc_OSError);
  static py::exception<gyrodrift::Error> other_error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const gyrodrift::UsageError& e) {  // OptionError included
      usage_error(e.what());
    } catch (const gyrodrift::DataError& e) {
      data_error(e.what());
    } catch (const gyrodrift::IoError& e) {
      file_error(e.what());
    } catch (const gyrodrift::Error& e) {
      other_error(e.what());
    }
  });

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
         const std::vector<bool>& logged) {
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
        return gp::Allan(x, s, logged);
      },
      arg("x"), py::kw_only(), arg("rate_hz"), arg("type") = allan_defaults.type,
      arg("dev") = allan_defaults.dev, arg("taus") = allan_defaults.taus,
      arg("units") = allan_defaults.units, arg("confidence") = allan_defaults.confidence,
      arg("threads") = allan_defaults.threads, arg("fit_tau_min") = allan_defaults.fit_tau_min_s,
      arg("fit_tau_max") = allan_defaults.fit_tau_max_s, arg("logged") = std::vector<bool>{});
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

  const gyrodrift::drift::FitSettings fd;
  py::class_<gp::PyDriftModel>(m, "DriftModel")
      .def(py::init<>())
      .def(
          "fit",
          [](gp::PyDriftModel& d, const gp::Array& y, const std::optional<gp::Array>& temperature,
             const std::string& mode, const std::string& method, const std::string& decomposition,
             const py::object& lags, const py::object& hidden, double rate_hz,
             const std::string& thermal_features, const std::vector<double>& time_constants,
             int ensemble, int realisations, std::uint64_t seed, int threads, bool nonlinear,
             std::optional<double> reference_temperature, const std::string& hysteresis,
             const std::string& target,
             const std::optional<std::vector<std::string>>& temperature_columns,
             const std::string& source, const std::vector<Eigen::Index>& record_starts,
             const std::vector<bool>& logged, const py::object& progress) {
            const gyrodrift::drift::FitSettings s{
                .mode = mode,
                .method = method,
                .decomposition = decomposition,
                .lags = gp::AutoOrIntegerSetting("lags", lags),
                .hidden = gp::AutoOrIntegerSetting("hidden", hidden),
                .rate_hz = rate_hz,
                .thermal_features = thermal_features,
                .time_constants = time_constants,
                .ensemble = ensemble,
                .realisations = realisations,
                .seed = seed,
                .threads = threads,
                .nonlinear = nonlinear,
                .reference_temperature = reference_temperature,
                .hysteresis = hysteresis,
                .has_temperature = temperature.has_value()};
            d.Fit(y, temperature, s, target, temperature_columns, source, record_starts, logged,
                  progress);
          },
          arg("y"), arg("temperature") = py::none(), py::kw_only(), arg("mode") = "compensate",
          arg("method") = fd.method, arg("decomposition") = fd.decomposition,
          arg("lags") = py::none(), arg("hidden") = fd.hidden, arg("rate_hz") = fd.rate_hz,
          arg("thermal_features") = fd.thermal_features, arg("time_constants") = fd.time_constants,
          arg("ensemble") = fd.ensemble, arg("realisations") = fd.realisations,
          arg("seed") = fd.seed, arg("threads") = fd.threads, arg("nonlinear") = fd.nonlinear,
          arg("reference_temperature") = py::none(), arg("hysteresis") = fd.hysteresis,
          arg("target") = "rate_dph", arg("temperature_columns") = py::none(),
          arg("source") = "python", arg("record_starts") = std::vector<Eigen::Index>{},
          arg("logged") = std::vector<bool>{}, arg("progress") = py::none())
      .def("estimate", &gp::PyDriftModel::Estimate, arg("temperature"), py::kw_only(),
           arg("record_starts") = std::vector<Eigen::Index>{})
      .def("compensate", &gp::PyDriftModel::Compensate, arg("temperature"), arg("y"), py::kw_only(),
           arg("record_starts") = std::vector<Eigen::Index>{})
      .def("compensation_summary", &gp::PyDriftModel::CompensationSummary, arg("temperature"),
           arg("y"), py::kw_only(), arg("record_starts") = std::vector<Eigen::Index>{})
      .def("coefficients", &gp::PyDriftModel::Coefficients, py::kw_only(),
           arg("reference_temperature") = py::none())
      .def("predict", &gp::PyDriftModel::Predict, arg("y"), arg("temperature") = py::none(),
           py::kw_only(), arg("horizon") = 1, arg("protocol") = "causal",
           arg("window") = gyrodrift::drift::CausalOptions{}.window, arg("threads") = 0,
           arg("progress") = py::none())
      .def("save", &gp::PyDriftModel::Save, arg("path"))
      .def_static("load_axes", &gp::PyDriftModel::LoadAxes, arg("path"))
      .def_static("save_axes", &gp::PyDriftModel::SaveAxes, arg("path"), arg("models"))
      .def_property_readonly("fitted", [](const gp::PyDriftModel& d) { return d.fitted_; })
      .def_property_readonly("summary", &gp::PyDriftModel::Summary)
      .def_property_readonly("sub_models", &gp::PyDriftModel::SubModels)
      .def_property_readonly(
          "mode",
          [](const gp::PyDriftModel& d) {
            return std::string(gyrodrift::drift::ToString(d.Loaded().model.options.mode));
          })
      .def_property_readonly(
          "method",
          [](const gp::PyDriftModel& d) {
            return std::string(gyrodrift::drift::ToString(d.Loaded().model.options.method));
          })
      .def_property_readonly(
          "target", [](const gp::PyDriftModel& d) { return d.Loaded().info.target_column; })
      .def_property_readonly("temperature_columns",
                             [](const gp::PyDriftModel& d) {
                               const std::string& t = d.Loaded().info.temperature_column;
                               return t.empty() ? std::vector<std::string>{} : gp::SplitColumns(t);
                             })
      .def_property_readonly("temperature_range_c", [](const gp::PyDriftModel& d) {
        return py::make_tuple(d.Loaded().model.temperature_min_c,
                              d.Loaded().model.temperature_max_c);
      });

  m.def(
      "temperature_warning",
      [](const gp::Array& t, const std::string& name) {
        return gyrodrift::drift::TemperatureWarning(gp::ToVector(t, "temperature"), name);
      },
      arg("temperature"), arg("name") = "temperature");
  const gyrodrift::selection::SelectionOptions sd;
  m.def("select_modes", &gp::SelectModesPy, arg("x"), arg("imfs"), arg("residue"), py::kw_only(),
        arg("criterion") = std::string(gyrodrift::selection::ToString(sd.criterion)),
        arg("distance") = std::string(gyrodrift::selection::ToString(sd.distance)),
        arg("realisations") = sd.monte_carlo.realisations,
        arg("confidence") = sd.monte_carlo.confidence, arg("seed") = sd.monte_carlo.seed,
        arg("band") = sd.band_confidence, arg("threads") = 0);
  const gyrodrift::drift::EvaluationOptions ed;
  m.def(
      "evaluate",
      [](const gp::Array& y, const std::optional<gp::Array>& temperature,
         const std::optional<gp::Array>& truth, const std::string& mode, const py::object& methods,
         const std::string& protocol, double split, int repeats, int horizon, int window,
         const std::string& decomposition, const py::object& lags, const py::object& hidden,
         double rate_hz, const std::string& thermal_features,
         const std::vector<double>& time_constants, int ensemble, int realisations,
         std::uint64_t seed, int threads, bool nonlinear,
         std::optional<double> reference_temperature, const std::string& hysteresis,
         const py::object& progress) {
        // The models' settings as fit's; the method is evaluate's list (ms-elm stands in).
        const gyrodrift::drift::FitSettings s{.mode = mode,
                                              .method = "ms-elm",
                                              .decomposition = decomposition,
                                              .lags = gp::AutoOrIntegerSetting("lags", lags),
                                              .hidden = gp::AutoOrIntegerSetting("hidden", hidden),
                                              .rate_hz = rate_hz,
                                              .thermal_features = thermal_features,
                                              .time_constants = time_constants,
                                              .ensemble = ensemble,
                                              .realisations = realisations,
                                              .seed = seed,
                                              .threads = threads,
                                              .nonlinear = nonlinear,
                                              .reference_temperature = reference_temperature,
                                              .hysteresis = hysteresis,
                                              .has_temperature = temperature.has_value()};
        return gp::Evaluate(y, temperature, truth, s, methods, protocol, split, repeats, horizon,
                            window, progress);
      },
      arg("y"), arg("temperature") = py::none(), arg("truth") = py::none(), py::kw_only(),
      arg("mode") = "predict", arg("methods") = "all", arg("protocol") = "both",
      arg("split") = ed.split, arg("repeats") = ed.repeats, arg("horizon") = ed.horizon,
      arg("window") = ed.causal.window, arg("decomposition") = fd.decomposition,
      arg("lags") = py::none(), arg("hidden") = fd.hidden, arg("rate_hz") = fd.rate_hz,
      arg("thermal_features") = fd.thermal_features, arg("time_constants") = fd.time_constants,
      arg("ensemble") = fd.ensemble, arg("realisations") = fd.realisations, arg("seed") = fd.seed,
      arg("threads") = fd.threads, arg("nonlinear") = fd.nonlinear,
      arg("reference_temperature") = py::none(), arg("hysteresis") = fd.hysteresis,
      arg("progress") = py::none());
  m.def("calibrate", &gp::Calibrate, arg("manifest_path"), arg("output_dir"), py::kw_only(),
        arg("force") = false, arg("threads") = 0);
  m.def("_calibrate_unit", &gp::CalibrateUnit, arg("manifest_path"), arg("index"),
        arg("output_dir"), arg("force") = false);
  m.def("_finish_fleet", &gp::FinishFleet, arg("manifest_path"), arg("output_dir"), arg("units"),
        arg("seconds"));
  m.def(
      "_manifest_serials",
      [](const std::string& path) {
        std::vector<std::string> serials;
        for (const auto& u : gp::LoadManifest(path).units) serials.push_back(u.serial);
        return serials;
      },
      arg("path"));
}
