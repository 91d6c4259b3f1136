#include "gyrodrift/fleet/calibration.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/common/statistics.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/records.h"
#include "gyrodrift/drift/temperature_check.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/compensate_task.h"
#include "gyrodrift/tasks/fit_task.h"
#include "unit_report.h"

namespace gyrodrift::fleet {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kSummaryFile = "summary.json";

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The first sample and length of the longest record.
std::pair<Eigen::Index, Eigen::Index> LongestRecord(Eigen::Index n,
                                                    const std::vector<Eigen::Index>& starts) {
  std::pair<Eigen::Index, Eigen::Index> longest{0, 0};
  drift::ForEachRecord(n, starts, [&](Eigen::Index begin, Eigen::Index length) {
    if (length > longest.second) longest = {begin, length};
  });
  return longest;
}

allan::NoiseTerms NoiseOf(const Eigen::Ref<const Eigen::VectorXd>& rate, double rate_hz, allan::RateUnit unit,
                          Eigen::VectorXd* tau, Eigen::VectorXd* adev) {
  allan::AllanOptions o;
  o.rate_hz = rate_hz;
  o.units = unit;
  o.deviation = allan::Deviation::kOadev;
  o.grid = allan::TauGrid::kOctave;
  const allan::AllanResult r = allan::Compute(rate, o, Execution{.threads = 1});
  *tau = r.tau_s();
  *adev = r.dev();
  return allan::IdentifyNoise(r);
}


// The limits a verification breaks, one phrase each. A set limit whose figure could not be
// measured is broken, not passed: a calibration tool must not pass what it did not check.
std::vector<std::string> Failures(const Limits& limits, const VerificationResult& v) {
  std::vector<std::string> out;
  if (!std::isnan(limits.residual_drift_rms) && !(v.drift_rms_after <= limits.residual_drift_rms)) {
    out.push_back(std::isnan(v.drift_rms_after)
                      ? std::string("residual drift not measured (the log is shorter than two "
                                    "drift_window_s blocks)")
                      : fmt::format("residual drift {:.4g} > {:.4g}", v.drift_rms_after,
                                    limits.residual_drift_rms));
  }
  if (!std::isnan(limits.bias_instability_dph)) {
    // Unidentified, B has no value (an empty cell); what bounds it is the curve's flattest point
    // read by the IEEE 952 slope method (min sigma / 0.664), so that bound must meet the limit.
    const allan::NoiseTerm& b = v.noise_after.b_dph;
    const double figure = b.identified ? b.value : b.slope_reading;
    if (!(figure <= limits.bias_instability_dph)) {
      out.push_back(fmt::format("bias instability {}{:.4g} > {:.4g} deg/h",
                                b.identified ? "" : "(not identified; bound min ADEV/0.664) ",
                                figure, limits.bias_instability_dph));
    }
  }
  if (!std::isnan(limits.removed_share_min) && !(v.truth_removed >= limits.removed_share_min)) {
    out.push_back(std::isnan(v.truth_removed)
                      ? std::string("removed share undefined (the true drift is zero)")
                      : fmt::format("removed {:.1f} % < {:.1f} %", 100.0 * v.truth_removed,
                                    100.0 * limits.removed_share_min));
  }
  return out;
}

Eigen::MatrixXd Temperatures(const io::CsvTable& table, const AxisSpec& axis) {
  Eigen::MatrixXd t(table.rows(), static_cast<Eigen::Index>(axis.temperature.size()));
  for (size_t c = 0; c < axis.temperature.size(); ++c) {
    t.col(static_cast<Eigen::Index>(c)) = table.Column(axis.temperature[c]);
  }
  return t;
}

// The figures of one axis on one verification log (`path`), from its compensation `c`: the
// compensate task's, the drift_window_s block means for the report, the Allan analysis before and
// after (of the longest record), and the limits broken.
VerificationResult Verification(const Manifest& m, const std::string& path, double rate_hz,
                                const std::vector<Eigen::Index>& record_starts,
                                const tasks::AxisCompensation& c, const Eigen::VectorXd& y,
                                const Eigen::VectorXd& truth) {
  VerificationResult v;
  v.log = PathFromManifest(m, path);
  v.samples = y.size();
  v.rate_hz = rate_hz;
  v.mean_before = c.summary.before.mean;
  v.mean_after = c.summary.after.mean;
  v.std_before = c.summary.before.std;
  v.std_after = c.summary.after.std;
  v.drift_rms_before = c.summary.before.slow;
  v.drift_rms_after = c.summary.after.slow;
  const auto block = std::max<Eigen::Index>(
      1, static_cast<Eigen::Index>(std::llround(m.drift_window_s * rate_hz)));
  v.output_means = drift::BlockMeans(y, block);
  v.compensated_means = drift::BlockMeans(c.compensated, block);
  v.estimate_means = drift::BlockMeans(c.estimate, block);
  v.block_hours.resize(v.output_means.size());
  for (Eigen::Index b = 0; b < v.block_hours.size(); ++b) {
    v.block_hours[b] =
        (static_cast<double>(b) + 0.5) * static_cast<double>(block) / rate_hz / 3600.0;
  }
  if (truth.size() > 0) {
    v.truth_means = drift::BlockMeans(truth, block);
    v.truth_removed = c.truth_removed;
  }
  v.outside_share = c.outside_share;
  // The Allan analysis needs uniform samples: of a log split at its gaps, its longest record.
  const auto [first, length] = LongestRecord(y.size(), record_starts);
  v.noise_before = NoiseOf(y.segment(first, length), rate_hz, m.rate_unit, &v.tau_s, &v.adev_before);
  Eigen::VectorXd tau_after;
  v.noise_after = NoiseOf(c.compensated.segment(first, length), rate_hz, m.rate_unit, &tau_after,
                          &v.adev_after);
  v.failures = Failures(m.limits, v);
  return v;
}

// A unit's calibration: one model per axis, fitted on the calibration logs as `gyrodrift fit`
// fits them (tasks::RunFit, one thread), and each axis's model figures and warnings.
struct FittedUnit {
  std::vector<io::LoadedModel> models;
  std::vector<AxisResult> axes;
};

// The temperature columns of every axis, each once (the warnings name each column once).
std::vector<std::string> TemperatureColumns(const Manifest& m) {
  std::vector<std::string> seen;
  for (const AxisSpec& axis : m.axes) {
    for (const std::string& column : axis.temperature) {
      if (std::find(seen.begin(), seen.end(), column) == seen.end()) seen.push_back(column);
    }
  }
  return seen;
}

// What the user must know about a log's inputs: an assumed sample rate, temperature columns of
// the axes that do not look like degC, each naming the log's file.
std::vector<std::string> Warnings(const Manifest& m, const tasks::TaskLog& log) {
  return tasks::LogWarnings(log, log.rate_how, TemperatureColumns(m), tasks::Audience::kManifest);
}

std::string Joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

// The figures of an axis's fitted model: its thermal sub-models' regressors, bias, skill and
// warnings (a warning: the run could not identify that sub-model).
AxisResult ModelFigures(const AxisSpec& axis, const io::LoadedModel& model) {
  AxisResult a;
  a.target = axis.target;
  a.temperature = model.info.temperature_column;
  a.model_summary = model.model.Summary();
  for (const drift::SubModel& sub : model.model.sub_models) {
    if (!sub.thermal) continue;
    const drift::ThermalRegression& t = *sub.thermal;
    if (model.model.sub_models.size() == 1) {
      a.regressors = t.RegressorNames(axis.temperature);
      a.bias = t.coefficients[0];
      a.cv_rmse = t.report.cv_rmse;
      a.skill = t.report.skill;
      if (t.autopilot.fitted()) {
        a.autopilot = t.autopilot.Summary();
        a.autopilot_kept = t.autopilot.share_kept;
      }
    }
    a.identified = a.identified.value_or(true) && t.report.warnings.empty();
    for (const std::string& w : t.report.warnings) a.warnings.push_back(sub.name + ": " + w);
    for (const std::string& w : t.report.advice) a.warnings.push_back(sub.name + ": advice: " + w);
  }
  return a;
}

FittedUnit FitUnit(const Manifest& m, const UnitSpec& unit) {
  // A verification that is a calibration log would judge the model on what it was fitted on.
  std::vector<std::string> logs = unit.calibration;
  logs.insert(logs.end(), unit.verification.begin(), unit.verification.end());
  io::RequireDistinctFiles(logs, "logs", "each log is calibration or verification, once");
  // A copy of a calibration log is no verification either: the model would be judged on what it
  // was fitted on (the same bytes under another name passed with the fit's own figures).
  for (const std::string& ver : unit.verification) {
    for (const std::string& cal : unit.calibration) {
      std::error_code a, b;
      if (fs::file_size(ver, a) != fs::file_size(cal, b) || a || b) continue;
      if (io::ReadTextFile(ver) != io::ReadTextFile(cal)) continue;
      throw DataError(
          fmt::format("verification log {} holds the bytes of calibration log {}: "
                      "verify on another run",
                      ver, cal));
    }
  }
  std::vector<tasks::TaskLog> cal;
  std::vector<std::string> warnings;
  for (const std::string& path : unit.calibration) {
    cal.push_back(tasks::ReadTaskLog(path, m.log, m.rate_hz));
    io::RequireSameSampleRate(unit.calibration.front(), cal.front().rate_hz, path,
                              cal.back().rate_hz);
    for (const std::string& w : Warnings(m, cal.back())) warnings.push_back(w);
  }
  // Units run in parallel (RunFleet's threads, or one Dask task per worker thread), so a unit
  // runs on one thread: a decomposing method (ms-elm, emd-elm) would otherwise take every core
  // per unit, T units x every core on the machine, and a one-thread Dask worker would use them
  // all. The results do not depend on it: the model is the one `fit` writes with any --threads.
  drift::FitSettings settings = m.fit;
  settings.threads = 1;
  FittedUnit fitted;
  for (const AxisSpec& axis : m.axes) {
    tasks::FitRun run = tasks::AssembleFitRun(cal, axis.target, Joined(axis.temperature), m.log,
                                              "target", "temperature");
    if (!unit.calibration_as_written.empty()) run.source = Joined(unit.calibration_as_written);
    tasks::FitResult fit = tasks::RunFit(run, settings, std::string(allan::ToString(m.rate_unit)), m.log);
    AxisResult a = ModelFigures(axis, fit.axes.front());
    a.warnings.insert(a.warnings.end(), warnings.begin(), warnings.end());
    fitted.axes.push_back(std::move(a));
    fitted.models.push_back(std::move(fit.axes.front()));
  }
  return fitted;
}

// One verification log (the k-th, 0-based) compensated by every axis's model: its output CSV, each
// axis's figures (appended to unit.axes[i].verification) and its Allan columns.
std::string VerifyLog(const Manifest& m, const UnitSpec& spec, size_t k,
                      const std::vector<io::LoadedModel>& models, UnitResult& unit,
                      std::vector<io::CsvColumn>& allan_columns) {
  const std::string& path = spec.verification[k];
  const tasks::TaskLog ver = tasks::ReadTaskLog(path, m.log, m.rate_hz);
  // Block means and the Allan analysis of the verification need the time grid of a log with
  // no made-up rows; carry serves duty-cycled calibration logs.
  if (m.log.gaps == io::GapPolicy::kCarry && !ver.logged.empty()) {
    throw DataError(fmt::format(
        "{}: gaps = 'carry' fills this verification log's gaps ({} of {} rows made up), but the "
        "verification's block means and Allan deviation need logged rows: verify on a "
        "continuous log",
        path, ver.table.rows() - drift::CountLogged(ver.logged, ver.table.rows()),
        ver.table.rows()));
  }
  tasks::RequireModelRate(models, "the unit's model", path, ver.rate_hz, ver.rate_how, false);
  const std::vector<std::string> warnings = Warnings(m, ver);
  for (AxisResult& a : unit.axes) a.warnings.insert(a.warnings.end(), warnings.begin(), warnings.end());
  std::vector<io::CsvColumn> columns;
  for (int c = 0; c < static_cast<int>(ver.table.header().size()); ++c) {
    columns.push_back({ver.table.header()[static_cast<size_t>(c)], ver.table.Column(c)});
  }
  for (size_t i = 0; i < m.axes.size(); ++i) {
    const AxisSpec& axis = m.axes[i];
    const Eigen::VectorXd truth =
        axis.truth.empty() ? Eigen::VectorXd() : ver.table.Column(axis.truth);
    // The figures `gyrodrift compensate` reports, the slow variation over drift_window_s; the
    // interpolated rows of gaps = 'interpolate' count as data here.
    const tasks::AxisCompensation c = tasks::CompensateAxis(
        models[i], ver.table.Column(axis.target), Temperatures(ver.table, axis), ver.record_starts,
        {}, truth, {.rate_hz = ver.rate_hz, .drift_window_s = m.drift_window_s});
    for (io::CsvColumn& column : c.Columns(m.axes.size() == 1 ? "" : "_" + axis.target)) {
      columns.push_back(std::move(column));
    }
    VerificationResult v = Verification(m, path, ver.rate_hz, ver.record_starts, c,
                                        ver.table.Column(axis.target), truth);
    // Every axis of one log has the same length, so the same taus.
    if (i == 0) allan_columns.push_back({fmt::format("tau_s_v{}", k + 1), v.tau_s});
    const std::string tag = fmt::format("{}_v{}", axis.target, k + 1);
    allan_columns.push_back({"adev_before_" + tag, v.adev_before});
    allan_columns.push_back({"adev_after_" + tag, v.adev_after});
    unit.axes[i].verification.push_back(std::move(v));
  }
  return io::RenderCsv(columns);
}

// Everything CalibrateUnit does, throwing on the unit's own errors.
UnitOutputs Calibrate(const Manifest& m, const UnitSpec& unit, const html::DygraphsAssets& assets) {
  UnitOutputs out;
  UnitResult& r = out.result;
  r.serial = unit.serial;
  FittedUnit fitted = FitUnit(m, unit);
  r.axes = std::move(fitted.axes);
  out.files.push_back({"model.json", io::RenderModelFile(fitted.models)});
  std::vector<io::CsvColumn> allan_columns;
  for (size_t k = 0; k < unit.verification.size(); ++k) {
    out.files.push_back({fmt::format("verification_{}_compensated.csv", k + 1),
                         VerifyLog(m, unit, k, fitted.models, r, allan_columns)});
  }
  // Verification logs of different lengths have different tau grids: shorter columns are padded
  // with nan to the longest.
  Eigen::Index longest = 0;
  for (const io::CsvColumn& c : allan_columns) longest = std::max(longest, c.values.size());
  for (io::CsvColumn& c : allan_columns) {
    const Eigen::Index n = c.values.size();
    c.values.conservativeResize(longest);
    c.values.tail(longest - n).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  out.files.push_back({"allan.csv", io::RenderCsv(allan_columns)});
  out.files.push_back({"report.html", RenderUnitReport(m, unit, r, assets)});
  return out;
}

json RowsJson(const std::vector<FleetRow>& rows) {
  json j = json::array();
  for (const FleetRow& row : rows) j.push_back(row.cells);
  return j;
}

std::string FileHash(std::string_view contents) {
  return fmt::format("fnv1a64:{:016x}", Fnv1a64(contents));
}

// A finished unit's rows from its summary.json when the fingerprint matches and every file the
// summary lists is in the folder with the hash it was written with; false otherwise (missing,
// damaged, another fingerprint or another column set, a file deleted or edited since: the unit
// is redone).
bool ReadFinished(const std::string& folder, const std::string& fingerprint,
                  std::vector<FleetRow>* rows) {
  const std::string path = (fs::path(folder) / kSummaryFile).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    const json j = json::parse(io::ReadTextFile(path));
    if (j.at("fingerprint").get<std::string>() != fingerprint) return false;
    if (j.at("columns").get<std::vector<std::string>>() != FleetColumns()) return false;
    for (const auto& [name, hash] : j.at("files").items()) {
      const std::string file = (fs::path(folder) / name).string();
      if (!fs::is_regular_file(file, ec) || FileHash(io::ReadTextFile(file)) != hash) return false;
    }
    for (const json& cells : j.at("rows")) {
      FleetRow row{cells.get<std::vector<std::string>>()};
      if (row.cells.size() != FleetColumns().size()) return false;
      rows->push_back(std::move(row));
    }
    return !rows->empty();
  } catch (const std::exception&) {
    rows->clear();
    return false;
  }
}

// A unit that could not be calibrated loses what an earlier run wrote for it, which its error row
// would contradict (a model.json from logs the manifest no longer names, a page saying PASS). The
// summary goes first, so that a removal cut short leaves an unfinished unit, not a finished one
// that is wrong; then the files it lists and the ones every unit has, nothing else of the folder,
// and the folder when that leaves it empty. Returns what could not be removed ("" when all was).
std::string RetractUnit(const std::string& folder) {
  const fs::path summary = fs::path(folder) / kSummaryFile;
  std::error_code ec;
  if (fs::is_symlink(folder, ec) || !fs::is_regular_file(summary, ec)) return "";
  std::set<std::string> names = {"model.json", "allan.csv", "report.html"};
  try {
    const json j = json::parse(io::ReadTextFile(summary.string()));
    for (const auto& [name, hash] : j.at("files").items()) names.insert(name);
  } catch (const std::exception&) {
    // A damaged summary: the names every unit's files have (below).
  }
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("verification_", 0) == 0 && name.ends_with("_compensated.csv"))
      names.insert(name);
  }
  std::string failed;
  auto remove = [&failed](const fs::path& path) {
    std::error_code error;
    if (!fs::remove(path, error) && error) failed += (failed.empty() ? "" : ", ") + path.string();
  };
  remove(summary);
  for (const std::string& name : names) {
    // Only names of the folder's own files (an edited summary could name others).
    if (name.empty() || fs::path(name).filename() != fs::path(name) || name == "." ||
        name == "..") {
      continue;
    }
    remove(fs::path(folder) / name);
  }
  fs::remove(folder, ec);  // fails, leaving it, unless it is empty
  return failed;
}

// What an error row adds when an earlier run's files stayed.
std::string Unretracted(const std::string& failed) {
  return failed.empty() ? "" : " (an earlier run's files could not be removed: " + failed + ")";
}

// The manifest and the logs of `unit` (of every unit when null).
std::vector<std::string> InputsOf(const Manifest& m, const UnitSpec* unit) {
  std::vector<std::string> inputs = {m.path};
  for (const UnitSpec& u : m.units) {
    if (unit && &u != unit) continue;
    for (const std::string& log : u.Logs()) inputs.push_back(log);
  }
  return inputs;
}

}  // namespace

void RequireInputsOutside(const Manifest& m, const UnitSpec* unit, const std::string& folder) {
  io::RequireInputsOutsideFolder(InputsOf(m, unit), folder);
}

bool AxisResult::pass() const {
  for (const VerificationResult& v : verification) {
    if (!v.failures.empty()) return false;
  }
  return true;
}

bool UnitResult::pass() const {
  if (!error.empty()) return false;
  for (const AxisResult& a : axes) {
    if (!a.pass()) return false;
  }
  return true;
}

UnitOutputs CalibrateUnit(const Manifest& manifest, const UnitSpec& unit,
                          const html::DygraphsAssets& assets) {
  const auto start = std::chrono::steady_clock::now();
  UnitOutputs out;
  try {
    out = Calibrate(manifest, unit, assets);
  } catch (const Error& e) {
    out = UnitOutputs{};
    out.result.serial = unit.serial;
    out.result.error = e.what();
  }
  out.result.seconds = Seconds(start);
  return out;
}

std::string FleetResult::Summary() const {
  // No unit calibrated in this run (all skipped or failed): no time per unit to give.
  const std::string per_unit =
      calibrated > 0 ? fmt::format(" ({:.2f} s per calibrated unit, median)", unit_seconds_median)
                     : "";
  return fmt::format(
      "{} units: {} calibrated, {} skipped (done before), {} failed their limits, {} could not be "
      "calibrated; {:.1f} s{}",
      units, calibrated, skipped, failed_limits, errors, seconds, per_unit);
}

UnitRun RunUnit(const Manifest& m, const UnitSpec& unit, const std::string& output_dir,
                bool force, const html::DygraphsAssets& assets) {
  RequireInputsOutside(m, &unit, output_dir);
  const std::string folder = (fs::path(output_dir) / unit.serial).string();
  const std::string summary = (fs::path(folder) / kSummaryFile).string();
  UnitRun run;
  // Every way a unit fails: its row says why, and what an earlier run wrote for it goes.
  auto fail = [&](UnitResult result) {
    result.error += Unretracted(RetractUnit(folder));
    run.rows = Rows(result);
    run.what = "error";
    return run;
  };
  std::string fingerprint;
  try {
    fingerprint = UnitFingerprint(m, unit);
  } catch (const Error& e) {
    UnitResult failed;
    failed.serial = unit.serial;
    failed.error = e.what();
    return fail(std::move(failed));
  }
  if (!force && ReadFinished(folder, fingerprint, &run.rows)) {
    run.what = "skipped";
    return run;
  }
  UnitOutputs outputs = CalibrateUnit(m, unit, assets);
  if (!outputs.result.error.empty()) return fail(std::move(outputs.result));
  run.rows = Rows(outputs.result);
  json hashes = json::object();
  std::vector<std::pair<std::string, std::string>> files;
  std::error_code ec;
  fs::create_directories(folder, ec);
  for (auto& [name, text] : outputs.files) {
    hashes[name] = FileHash(text);
    files.push_back({(fs::path(folder) / name).string(), std::move(text)});
  }
  const json s = {{"fingerprint", fingerprint},
                  {"serial", unit.serial},
                  {"columns", FleetColumns()},
                  {"rows", RowsJson(run.rows)},
                  {"files", hashes}};
  files.push_back({summary, s.dump(1) + "\n"});
  try {
    io::WriteFilesAtomically(files, InputsOf(m, nullptr));  // a link could lead to any unit's log
    run.what = "calibrated";
    run.seconds = outputs.result.seconds;
  } catch (const Error& e) {
    outputs.result.error = e.what();
    return fail(std::move(outputs.result));
  }
  return run;
}

FleetResult FinishFleet(const Manifest& m, const std::string& output_dir,
                        const std::vector<UnitRun>& units, double seconds,
                        const html::DygraphsAssets& assets) {
  if (units.size() != m.units.size()) {
    throw UsageError("FinishFleet: " + std::to_string(units.size()) + " unit runs for a manifest of " +
                     std::to_string(m.units.size()) + " units");
  }
  FleetResult fleet;
  fleet.units = static_cast<int>(units.size());
  std::vector<double> calibrated_seconds;
  for (const UnitRun& run : units) {
    fleet.calibrated += run.what == "calibrated";
    fleet.skipped += run.what == "skipped";
    bool error = false, fail = false;
    for (const FleetRow& row : run.rows) {
      error |= row.cells[3] == "error";
      fail |= row.cells[3] == "fail";
      fleet.rows.push_back(row);
    }
    fleet.errors += error;
    fleet.failed_limits += fail && !error;
    if (run.seconds >= 0.0) calibrated_seconds.push_back(run.seconds);
  }
  FlagOutliers(fleet.rows);
  fleet.unit_seconds_median = Median(calibrated_seconds);

  std::string csv;
  auto quote = [](const std::string& cell) {
    if (cell.find_first_of(",\"\n") == std::string::npos) return cell;
    std::string q = "\"";
    for (char ch : cell) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
  };
  for (size_t c = 0; c < FleetColumns().size(); ++c) csv += (c ? "," : "") + FleetColumns()[c];
  csv += "\n";
  for (const FleetRow& row : fleet.rows) {
    for (size_t c = 0; c < row.cells.size(); ++c) csv += (c ? "," : "") + quote(row.cells[c]);
    csv += "\n";
  }
  fleet.seconds = seconds;
  io::WriteFilesAtomically(
      {{(fs::path(output_dir) / kFleetTableFile).string(), csv},
       {(fs::path(output_dir) / kFleetReportFile).string(), RenderFleetReport(m, fleet, assets)}},
      InputsOf(m, nullptr));
  return fleet;
}

FleetResult RunFleet(const Manifest& m, const FleetOptions& o, const FleetContext& context) {
  ValidateThreads(context.threads);
  RequireInputsOutside(m, nullptr, o.output_dir);
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  fs::create_directories(o.output_dir, ec);
  if (!fs::is_directory(o.output_dir, ec)) {
    throw IoError(o.output_dir + ": cannot create the output folder");
  }
  // A folder that exists but cannot be written would fail every unit and then the table.
  io::RequireOutputsAreNotInputs(InputsOf(m, nullptr),
                                 {(fs::path(o.output_dir) / kFleetTableFile).string(),
                                  (fs::path(o.output_dir) / kFleetReportFile).string()});
  const html::DygraphsAssets assets = html::LoadDygraphs();
  const int n = static_cast<int>(m.units.size());
  std::vector<UnitRun> runs(static_cast<size_t>(n));
  std::mutex mutex;
  int done = 0;
  ParallelFor(n, ResolveThreads(context.threads), [&](int task, int /*worker*/) {
    const UnitSpec& unit = m.units[static_cast<size_t>(task)];
    UnitRun run = RunUnit(m, unit, o.output_dir, o.force, assets);
    std::lock_guard<std::mutex> lock(mutex);
    const std::string what = run.what;
    runs[static_cast<size_t>(task)] = std::move(run);
    ++done;
    if (context.progress) context.progress(done, n, unit.serial, what);
  });
  // The time of the whole run, fleet.csv and fleet.html being the last bit of it.
  return FinishFleet(m, o.output_dir, runs, Seconds(start), assets);
}

}  // namespace gyrodrift::fleet
