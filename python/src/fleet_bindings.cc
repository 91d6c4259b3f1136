// The fleet: calibrate and the helpers of gyrodrift.fleet (Dask).
#include "bindings.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
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

namespace gyrodrift::python {
namespace {

namespace al = gyrodrift::allan;
namespace dec = gyrodrift::decomposition;
namespace sim = gyrodrift::simulation;
namespace gp = gyrodrift::python;

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

// Reports the units done to `progress` and stops at Ctrl-C once the units under way are written
// (a unit is all there or not there; those done stay, and a rerun skips them).
py::dict Calibrate(const std::string& manifest_path, const std::string& output_dir, bool force,
                   int threads, py::object progress) {
  ValidateThreads(threads);
  LongCall call(std::move(progress));
  const auto hook = call.Hook();
  fleet::FleetResult r;
  call.Run([&] {
    const fleet::Manifest m = LoadManifest(manifest_path);
    fleet::FleetOptions o;
    o.output_dir = output_dir;
    o.force = force;
    fleet::FleetContext context;
    context.threads = threads;
    context.progress = [&hook](int done, int total, const std::string&, const std::string&) {
      hook(static_cast<double>(done) / static_cast<double>(total), "");
    };
    r = fleet::RunFleet(m, o, context);
  });
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
                         html::LoadDygraphs());
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
    r = fleet::FinishFleet(m, output_dir, runs, seconds, html::LoadDygraphs());
  }
  return FleetDict(r);
}

}  // namespace

void BindFleet(py::module_& m) {
  using py::arg;
  m.def("calibrate", &gp::Calibrate, arg("manifest_path"), arg("output_dir"), py::kw_only(),
        arg("force") = false, arg("threads") = 0, arg("progress") = py::none());
  m.def("_calibrate_unit", &gp::CalibrateUnit, arg("manifest_path"), arg("index"),
        arg("output_dir"), arg("force") = false);
  m.def("_finish_fleet", &gp::FinishFleet, arg("manifest_path"), arg("output_dir"), arg("units"),
        arg("seconds"));
  m.def(
      "_manifest_serials",
      [](const std::string& path, const std::string& output_dir) {
        const fleet::Manifest m = gp::LoadManifest(path);
        if (!output_dir.empty()) fleet::RequireInputsOutside(m, nullptr, output_dir);
        std::vector<std::string> serials;
        for (const auto& u : m.units) serials.push_back(u.serial);
        return serials;
      },
      arg("path"), arg("output_dir") = "");
}

}  // namespace gyrodrift::python
