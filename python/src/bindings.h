// Private to python/src: what the binding files of _gyrodrift share (module.cc lists them): the
// conversions between numpy arrays and Eigen, task-layer records as Python objects, and LongCall,
// which runs a library call without the GIL, with progress and Ctrl-C.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <signal.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/execution.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/fit_settings.h"

namespace gyrodrift::python {

namespace py = pybind11;

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A 1-D float64 copy of any array-like (lists, float32, strided views), checked under the GIL so
// the computation can run without it; `name` names the argument in errors.
Eigen::VectorXd ToVector(const Array& a, const char* name);
// A 2-D copy (a 1-D array is one column).
Eigen::MatrixXd ToMatrix(const Array& a, const char* name);
py::array_t<double> ToArray(const Eigen::VectorXd& v);
py::array_t<double, py::array::f_style> ToArray(const Eigen::MatrixXd& m);
// A record of the task layer as Python objects: the dict the sidecar's JSON object would load as,
// but with NaN kept as NaN (the JSON file writes null).
py::object ToPython(const nlohmann::json& j);
// The fit settings of a call (DriftModel.fit, evaluate) from its keyword arguments, read by their
// one reader (tasks::FitSettingsFromJson) onto `base`: every drift::FitSettings field is a keyword
// of its name, so a field added there reaches Python with no edit here. None leaves a setting at
// its default; a keyword that names no setting, or one the call sets itself (`own`: mode,
// has_temperature, evaluate's method), raises TypeError naming it; a wrong value raises the
// reader's OptionError (UsageError) naming it.
drift::FitSettings FitSettingsOf(const py::kwargs& keywords, drift::FitSettings base,
                                 const char* function, const std::vector<std::string>& own);
// Before the work, as the CLI's fit, evaluate and compensate: a UserWarning for each column of
// `temperature` that does not look like degC (drift::TemperatureWarning), named by `names`.
void WarnOfTemperatures(const Eigen::MatrixXd& temperature, const std::vector<std::string>& names);
// The names of arrays' temperature columns: temperature_c, or temperature_c1, temperature_c2, ...
std::vector<std::string> TemperatureNames(Eigen::Index columns);

// The settings keywords and their defaults, drift::FitSettings{} as JSON without the fields no
// call takes as a keyword (mode: a keyword of its own; has_temperature: set from temperature):
// gd.fit_defaults().
nlohmann::json FitKeywordDefaults();

// Ctrl-C during a long call. Python runs its SIGINT handler's work on the main thread only, between
// bytecodes, which a call inside the library never reaches. So while any long call runs, SIGINT
// first goes to InterruptHandler: it counts the interrupt, which every running call's progress
// hook sees, and hands the signal on to the handler it replaced (Python's, which marks the
// KeyboardInterrupt pending as usual). The last call to end puts that handler back.
extern std::atomic<unsigned> g_interrupts;
extern std::mutex g_sigint_mutex;
extern int g_running_calls;                 // guarded by g_sigint_mutex
extern bool g_handler_installed;            // guarded by g_sigint_mutex
extern struct sigaction g_replaced_sigint;  // written before ours is installed, read by it
extern "C" void InterruptHandler(int signal, siginfo_t* info, void* context);

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

// The Execution of a long call's `threads` keyword (as drift::MakeExecution maps it), reporting
// to the call's progress callable; checked before any work (OptionError naming `threads`).
inline Execution ExecutionOf(int threads, LongCall& call) {
  const Execution execution{.threads = threads, .progress = call.Hook()};
  execution.Validate();
  return execution;
}

// The causal protocol's keywords (window, mirror, windows, causal_ensemble): a refusal of a
// drift::CausalOptions field under `causal.` names its keyword, as the CLI's names its flag.
inline drift::CausalOptions CausalOf(int window, double mirror, int windows, int causal_ensemble) {
  return {.window = window, .ensemble_size = causal_ensemble, .mirror = mirror, .windows = windows};
}
template <typename Validate>
void ValidateAsCausalKeywords(Validate&& validate) {
  ValidateAsSettings({{"causal.window", "window"},
                      {"causal.mirror", "mirror"},
                      {"causal.windows", "windows"},
                      {"causal.ensemble_size", "causal_ensemble"}},
                     std::forward<Validate>(validate));
}

// The functions of each binding file, called by PYBIND11_MODULE (module.cc).
void BindSignal(py::module_& m);      // decompose, allan, noise_terms, simulate, select_modes
void BindDriftModel(py::module_& m);  // DriftModel, temperature_warning, fit_defaults
void BindExport(py::module_& m);      // export (model files for firmware and PX4)
void BindEvaluate(py::module_& m);    // evaluate
void BindFleet(py::module_& m);       // calibrate and the fleet's helpers
void BindLogs(py::module_& m);        // read_ulog, ulog_columns, plan
void BindDemo(py::module_& m);        // demo (the whole study, its folder)

}  // namespace gyrodrift::python
