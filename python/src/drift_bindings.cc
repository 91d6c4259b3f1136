// DriftModel: fit, estimate, compensate, predict, save and load (as the CLI's fit, compensate,
// predict and export read a model file), temperature_warning and fit_defaults; export.
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
#include "gyrodrift/firmware/export.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/fleet/manifest.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/tasks/allan_task.h"
#include "gyrodrift/tasks/compensate_task.h"
#include "gyrodrift/tasks/decompose_task.h"
#include "gyrodrift/tasks/fit_task.h"
#include "gyrodrift/tasks/predict_task.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::python {
namespace {

namespace al = gyrodrift::allan;
namespace dec = gyrodrift::decomposition;
namespace sim = gyrodrift::simulation;
namespace gp = gyrodrift::python;

// One axis of a model file: the fitted model and the column names it was fitted on.
class PyDriftModel {
 public:
  PyDriftModel() = default;
  explicit PyDriftModel(io::LoadedModel loaded) : loaded_(std::move(loaded)), fitted_(true) {}

  // As `gyrodrift fit`: tasks::RunFit on the run of the arrays.
  void Fit(const Array& y_in, const std::optional<Array>& temperature_in,
           const drift::FitSettings& settings, const std::string& target,
           const std::optional<std::vector<std::string>>& temperature_columns,
           const std::string& source, const std::string& units,
           const std::vector<Eigen::Index>& record_starts, const std::vector<bool>& logged,
           const py::object& progress) {
    LongCall call(progress);
    settings.Validate();  // option errors before the arrays are looked at
    (void)allan::RateUnitFromString(units);
    const Execution execution = ExecutionOf(settings.threads, call);

    const Eigen::VectorXd y = ToVector(y_in, "y");
    Eigen::MatrixXd temperature;
    if (temperature_in) temperature = ToMatrix(*temperature_in, "temperature");
    const std::vector<std::string> names =
        temperature_columns ? *temperature_columns : TemperatureNames(temperature.cols());
    if (temperature_in && static_cast<Eigen::Index>(names.size()) != temperature.cols()) {
      throw UsageError("temperature_columns: " + std::to_string(names.size()) + " names for " +
                       std::to_string(temperature.cols()) + " temperature columns");
    }
    WarnOfTemperatures(temperature, names);
    // One target: the run of the arrays, as tasks::AssembleFitRun makes it of logs.
    tasks::FitRun run{.targets = {target}, .temperatures = {}, .rows = {}, .source = source};
    if (temperature_in) run.temperatures = names;
    Eigen::MatrixXd rows(y.size(), 1 + temperature.cols());
    rows.col(0) = y;
    if (temperature.cols() > 0) {
      if (temperature.rows() != y.size()) {
        throw DataError("temperature has " + std::to_string(temperature.rows()) +
                        " samples, the target " + std::to_string(y.size()) + ": they must match");
      }
      rows.rightCols(temperature.cols()) = temperature;
    }
    run.rows.Append(rows, record_starts, logged);
    tasks::FitResult fit;
    call.Run([&] {
      fit = tasks::RunFit(run, settings, units, {},
                          [&execution](int, double fraction, std::string_view step) {
                            if (execution.progress) execution.progress(fraction, step);
                          });
    });
    loaded_ = std::move(fit.axes.front());
    fitted_ = true;
  }

  const io::LoadedModel& Loaded() const {
    if (!fitted_) throw UsageError("DriftModel: not fitted (call fit() or DriftModel.load())");
    return loaded_;
  }

  // The model's temperature columns, as its file names them.
  std::vector<std::string> Channels() const {
    return tasks::SplitColumns(Loaded().info.temperature_column);
  }

  void RequireMode(drift::Mode mode, const char* what) const {
    if (Loaded().model.options.mode != mode) {
      throw UsageError(std::string(what) + ": needs a model fitted with mode '" +
                       std::string(drift::ToString(mode)) + "', this one is '" +
                       std::string(drift::ToString(Loaded().model.options.mode)) + "'");
    }
  }

  // tasks::CompensateAxis of y (or of zeros: the estimate alone), as `gyrodrift compensate`;
  // the figures over the `logged` rows (empty: every row) against `truth` (None: no truth).
  tasks::AxisCompensation Compensation(const char* what, const Array& temperature_in,
                                       const Array* y_in,
                                       const std::vector<Eigen::Index>& record_starts,
                                       const tasks::CompensateSettings& settings = {},
                                       const std::vector<bool>& logged = {},
                                       const std::optional<Array>& truth_in = std::nullopt,
                                       std::optional<double> rate_hz = std::nullopt) const {
    RequireMode(drift::Mode::kCompensate, what);
    if (rate_hz) {
      RequireInRange("rate_hz", *rate_hz, 1e-9, 1e9);
      tasks::RequireModelRate({Loaded()}, "the model", "the data", *rate_hz, "given", false);
    }
    const Eigen::MatrixXd t = ToMatrix(temperature_in, "temperature");
    const Eigen::VectorXd y = y_in ? ToVector(*y_in, "y") : Eigen::VectorXd::Zero(t.rows());
    if (y.size() != t.rows()) {
      throw DataError(std::string(what) + ": y has " + std::to_string(y.size()) +
                      " samples, temperature " + std::to_string(t.rows()));
    }
    const Eigen::VectorXd truth = truth_in ? ToVector(*truth_in, "truth") : Eigen::VectorXd();
    if (truth_in && truth.size() != t.rows()) {
      throw DataError(std::string(what) + ": truth has " + std::to_string(truth.size()) +
                      " samples, temperature " + std::to_string(t.rows()));
    }
    const std::vector<std::string> channels = Channels();
    if (t.cols() == static_cast<Eigen::Index>(channels.size())) WarnOfTemperatures(t, channels);
    tasks::CompensateSettings timed = settings;  // a stated rate times the blocks, as --rate-hz
    if (rate_hz) timed.rate_hz = *rate_hz;
    py::gil_scoped_release release;
    return tasks::CompensateAxis(Loaded(), y, t, record_starts, logged, truth, timed);
  }

  py::tuple Estimate(const Array& temperature_in, const std::vector<Eigen::Index>& record_starts,
                     std::optional<double> rate_hz) const {
    const tasks::AxisCompensation c = Compensation("estimate", temperature_in, nullptr,
                                                   record_starts, {}, {}, std::nullopt, rate_hz);
    return py::make_tuple(ToArray(c.estimate), ToArray(c.sd));
  }

  // y - estimate, as `gyrodrift compensate` writes it.
  py::array_t<double> Compensate(const Array& temperature_in, const Array& y_in,
                                 const std::vector<Eigen::Index>& record_starts,
                                 std::optional<double> rate_hz) const {
    return ToArray(Compensation("compensate", temperature_in, &y_in, record_starts, {}, {},
                                std::nullopt, rate_hz)
                       .compensated);
  }

  // The figures `gyrodrift compensate` prints and keeps in its sidecar for y compensated by this
  // model (at the model's sample rate).
  py::dict CompensationSummary(const Array& temperature_in, const Array& y_in,
                               const std::vector<Eigen::Index>& record_starts,
                               double drift_window_s, const std::vector<bool>& logged,
                               const std::optional<Array>& truth,
                               std::optional<double> rate_hz) const {
    const tasks::AxisCompensation c =
        Compensation("compensation_summary", temperature_in, &y_in, record_starts,
                     {.drift_window_s = drift_window_s}, logged, truth, rate_hz);
    const drift::CompensationSummary& s = c.summary;
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
    // As the sidecar of `gyrodrift compensate`: the share of the rows outside the calibration's
    // temperatures, the mean drift_sd (identified models) and, with a truth, its share removed.
    d["outside_share"] = c.outside_share;
    d["drift_sd_mean"] = c.drift_sd_mean;
    if (c.has_truth) {
      d["truth_rms"] = c.truth_rms;
      d["residual_rms"] = c.residual_rms;
      d["truth_removed"] = c.truth_removed;
    }
    return d;
  }

  // The thermal sub-models' coefficients in physical units around `reference_temperature`, else
  // the model's reference temperature, else the calibration's means (as `gyrodrift fit` prints).
  py::list Coefficients(std::optional<double> reference_temperature) const {
    // The range fit's reference_temperature takes (drift::FitSettings).
    if (reference_temperature) {
      RequireInRange("reference_temperature", *reference_temperature, -100.0, 200.0);
    }
    const io::LoadedModel& l = Loaded();
    const std::vector<std::string> channels = tasks::SplitColumns(l.info.temperature_column);
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

  // As `gyrodrift predict` (tasks::RunPredict): predictions of y[t] for t = first .. N-1.
  py::tuple Predict(const Array& y_in, const std::optional<Array>& temperature_in, int horizon,
                    const std::string& protocol, int window, double mirror, int windows,
                    int causal_ensemble, int threads, const py::object& progress,
                    std::optional<double> rate_hz) const {
    RequireMode(drift::Mode::kPredict, "predict");
    if (rate_hz) {
      RequireInRange("rate_hz", *rate_hz, 1e-9, 1e9);
      tasks::RequirePredictRate(Loaded(), "the model", "the data", *rate_hz, "given", false);
    }
    LongCall call(progress);
    const tasks::PredictSettings settings{
        .protocol = protocol,
        .causal = CausalOf(window, mirror, windows, causal_ensemble),
        .horizon = horizon,
        .threads = threads};
    ValidateAsCausalKeywords([&] { settings.Validate(); });
    const Eigen::VectorXd y = ToVector(y_in, "y");
    Eigen::VectorXd temperature;
    if (Loaded().model.uses_temperature()) {
      if (!temperature_in) throw UsageError("predict: this model needs temperature");
      temperature = ToVector(*temperature_in, "temperature");
    }
    tasks::PredictResult r;
    call.Run([&] { r = tasks::RunPredict(Loaded(), y, temperature, settings, "y", call.Hook()); });
    return py::make_tuple(r.first, ToArray(r.prediction));
  }

  void Save(const std::string& path) const { io::WriteModelFile(path, {Loaded()}); }

  // The model file's text and back (pickling: a model sent to a Dask worker or a process pool).
  std::string ToText() const { return io::RenderModelFile({Loaded()}); }
  static PyDriftModel FromText(const std::string& text) {
    std::vector<io::LoadedModel> axes = io::ParseModelFileAxes(text, "a pickled DriftModel");
    if (axes.size() != 1) throw DataError("a pickled DriftModel holds one axis");
    return PyDriftModel(std::move(axes.front()));
  }

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
    const std::vector<std::string> channels = tasks::SplitColumns(l.info.temperature_column);
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
        if (t.autopilot.fitted()) {
          py::dict a;
          a["degree"] = t.autopilot.degree;
          a["tref_c"] = t.autopilot.tref_c;
          a["tmin_c"] = t.autopilot.tmin_c;
          a["tmax_c"] = t.autopilot.tmax_c;
          a["coefficients"] = std::vector<double>(t.autopilot.coefficients.begin(),
                                                  t.autopilot.coefficients.end());
          a["share_kept"] = t.autopilot.share_kept;
          a["summary"] = t.autopilot.Summary();
          th["autopilot"] = a;
        } else {
          th["autopilot"] = py::none();
        }
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

// DriftModel.fit: its own keywords, then the fit settings as keywords (FitSettingsOf).
void FitKeywords(gp::PyDriftModel& d, const gp::Array& y,
                 const std::optional<gp::Array>& temperature, const std::string& mode,
                 const std::string& target,
                 const std::optional<std::vector<std::string>>& temperature_columns,
                 const std::string& source, const std::string& units,
                 const std::vector<Eigen::Index>& record_starts, const std::vector<bool>& logged,
                 const py::object& progress, const py::kwargs& settings) {
  const gyrodrift::drift::FitSettings s = gp::FitSettingsOf(
      settings, {.mode = mode, .has_temperature = temperature.has_value()}, "fit", {});
  d.Fit(y, temperature, s, target, temperature_columns, source, units, record_starts, logged,
        progress);
}

}  // namespace

void BindDriftModel(py::module_& m) {
  using py::arg;
  const gyrodrift::tasks::PredictSettings pd;
  // mode has no library default (fit --mode is required): compensate is Python's.
  py::class_<gp::PyDriftModel>(m, "DriftModel")
      .def(py::init<>())
      .def("fit", &FitKeywords, arg("y"), arg("temperature") = py::none(), py::kw_only(),
           arg("mode") = "compensate", arg("target") = "rate_dph",
           arg("temperature_columns") = py::none(), arg("source") = "python",
           arg("units") = gyrodrift::io::ModelFileInfo{}.rate_unit,
           arg("record_starts") = std::vector<Eigen::Index>{}, arg("logged") = std::vector<bool>{},
           arg("progress") = py::none())
      .def("estimate", &gp::PyDriftModel::Estimate, arg("temperature"), py::kw_only(),
           arg("record_starts") = std::vector<Eigen::Index>{}, arg("rate_hz") = py::none())
      .def("compensate", &gp::PyDriftModel::Compensate, arg("temperature"), arg("y"), py::kw_only(),
           arg("record_starts") = std::vector<Eigen::Index>{}, arg("rate_hz") = py::none())
      .def("compensation_summary", &gp::PyDriftModel::CompensationSummary, arg("temperature"),
           arg("y"), py::kw_only(), arg("record_starts") = std::vector<Eigen::Index>{},
           arg("drift_window_s") = gyrodrift::tasks::CompensateSettings{}.drift_window_s,
           arg("logged") = std::vector<bool>{}, arg("truth") = py::none(),
           arg("rate_hz") = py::none())
      .def("coefficients", &gp::PyDriftModel::Coefficients, py::kw_only(),
           arg("reference_temperature") = py::none())
      .def("predict", &gp::PyDriftModel::Predict, arg("y"), arg("temperature") = py::none(),
           py::kw_only(), arg("horizon") = pd.horizon, arg("protocol") = pd.protocol,
           arg("window") = pd.causal.window, arg("mirror") = pd.causal.mirror,
           arg("windows") = pd.causal.windows, arg("causal_ensemble") = pd.causal.ensemble_size,
           arg("threads") = pd.threads, arg("progress") = py::none(), arg("rate_hz") = py::none())
      .def("save", &gp::PyDriftModel::Save, arg("path"))
      .def("to_text", &gp::PyDriftModel::ToText)
      .def_static("from_text", &gp::PyDriftModel::FromText, arg("text"))
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
      .def_property_readonly(
          "rate_hz",
          [](const gp::PyDriftModel& d) { return d.Loaded().model.options.features.rate_hz; })
      .def_property_readonly("temperature_columns",
                             [](const gp::PyDriftModel& d) {
                               const std::string& t = d.Loaded().info.temperature_column;
                               return t.empty() ? std::vector<std::string>{}
                                                : gyrodrift::tasks::SplitColumns(t);
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
  m.def(
      "fit_defaults", [] { return gp::ToPython(gp::FitKeywordDefaults()); },
      "The fit settings DriftModel.fit and evaluate take as keywords, with their defaults (the "
      "library's drift::FitSettings).");
}

void BindExport(py::module_& m) {
  using py::arg;
  namespace fw = gyrodrift::firmware;
  const fw::ExportOptions ed;
  m.def(
      "export",
      [](const py::list& models, const std::string& format, bool single_precision,
         const std::string& prefix, const std::vector<std::uint32_t>& device_ids) {
        const fw::ExportOptions options{.format = fw::ExportFormatFromString(format),
                                        .single_precision = single_precision,
                                        .prefix = prefix,
                                        .device_ids = device_ids};
        // Model files, or models fitted or loaded here (one axis each), not both.
        std::vector<std::string> paths;
        std::vector<io::LoadedModel> axes;
        for (const py::handle item : models) {
          if (py::isinstance<PyDriftModel>(item)) {
            axes.push_back(item.cast<const PyDriftModel&>().Loaded());
          } else {
            paths.push_back(item.cast<std::string>());
          }
        }
        if (!paths.empty() && !axes.empty()) {
          throw UsageError("models: give model files or DriftModel objects, not both");
        }
        return paths.empty() ? fw::ExportAxes(std::move(axes), options).text
                             : fw::ExportModelFiles(paths, options).text;
      },
      arg("models"), py::kw_only(), arg("format") = std::string(fw::ToString(ed.format)),
      arg("single_precision") = ed.single_precision, arg("prefix") = ed.prefix,
      arg("device_ids") = ed.device_ids);
}

}  // namespace gyrodrift::python
