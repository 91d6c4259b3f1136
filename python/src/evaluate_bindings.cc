// evaluate: the methods compared on a chronological split, as `gyrodrift evaluate`.
#include <sstream>

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
#include "gyrodrift/tasks/evaluate_task.h"

namespace gyrodrift::python {
namespace {

namespace al = gyrodrift::allan;
namespace dec = gyrodrift::decomposition;
namespace sim = gyrodrift::simulation;
namespace gp = gyrodrift::python;

// The method list as text: a string as given, a sequence joined by commas (tasks::ParseMethods).
std::string MethodList(const py::object& methods) {
  if (py::isinstance<py::str>(methods)) return methods.cast<std::string>();
  std::vector<std::string> names;
  try {
    names = methods.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {  // pybind's own message names no argument
    throw OptionError("methods", py::str(py::repr(methods)).cast<std::string>(),
                      "a method name or a sequence of them");
  }
  std::string text;
  for (const std::string& name : names) {
    text += (text.empty() ? "" : ",") + name;
  }
  if (text.empty()) throw OptionError("methods", "(empty)", "at least one method");
  return text;
}

// As `gyrodrift evaluate` (tasks::RunEvaluate): the rows as dicts.
py::dict Evaluate(const Array& y_in, const std::optional<Array>& temperature_in,
                  const std::optional<Array>& truth_in, const tasks::EvaluateSettings& settings,
                  const py::object& progress) {
  LongCall call(progress);
  ValidateAsCausalKeywords([&] { settings.Validate(); });
  (void)ExecutionOf(settings.fit.threads, call);
  const Eigen::VectorXd y = ToVector(y_in, "y");
  Eigen::MatrixXd temperature;
  if (temperature_in) temperature = ToMatrix(*temperature_in, "temperature");
  WarnOfTemperatures(temperature, TemperatureNames(temperature.cols()));
  Eigen::VectorXd truth;
  if (truth_in) truth = ToVector(*truth_in, "truth");
  tasks::EvaluateRun run;
  call.Run([&] { run = tasks::RunEvaluate(y, temperature, truth, settings, call.Hook()); });
  const drift::EvaluationResult& result = run.result;

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
  // The CLI's notes after its table, one line each (as read_log's notes).
  std::vector<std::string> notes;
  std::istringstream lines(tasks::EvaluateNotes(run));
  for (std::string line; std::getline(lines, line);) notes.push_back(line);
  out["notes"] = notes;
  return out;
}

}  // namespace

void BindEvaluate(py::module_& m) {
  using py::arg;
  const gyrodrift::tasks::EvaluateSettings ed;
  // The fit settings are keywords (FitSettingsOf) but method: evaluate compares `methods`.
  m.def(
      "evaluate",
      [](const gp::Array& y, const std::optional<gp::Array>& temperature,
         const std::optional<gp::Array>& truth, const std::string& mode, const py::object& methods,
         const std::string& protocol, double split, int repeats, int horizon, int window,
         double mirror, int windows, int causal_ensemble, const py::object& progress,
         const py::kwargs& settings) {
        const gyrodrift::tasks::EvaluateSettings s{
            .fit = gp::FitSettingsOf(
                settings,
                {.mode = mode, .method = "ms-elm", .has_temperature = temperature.has_value()},
                "evaluate", {"method"}),
            .methods = gp::MethodList(methods),
            .protocol = protocol,
            .split = split,
            .repeats = repeats,
            .causal = gp::CausalOf(window, mirror, windows, causal_ensemble),
            .horizon = horizon};
        return gp::Evaluate(y, temperature, truth, s, progress);
      },
      arg("y"), arg("temperature") = py::none(), arg("truth") = py::none(), py::kw_only(),
      arg("mode") = "predict", arg("methods") = ed.methods, arg("protocol") = ed.protocol,
      arg("split") = ed.split, arg("repeats") = ed.repeats, arg("horizon") = ed.horizon,
      arg("window") = ed.causal.window, arg("mirror") = ed.causal.mirror,
      arg("windows") = ed.causal.windows, arg("causal_ensemble") = ed.causal.ensemble_size,
      arg("progress") = py::none());
}

}  // namespace gyrodrift::python
