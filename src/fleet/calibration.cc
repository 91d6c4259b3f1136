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
#include "gyrodrift/common/statistics.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/temperature_check.h"
#include "gyrodrift/drift/features.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/io/model_file.h"
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

std::string Fmt(double v) { return std::isnan(v) ? "" : io::FormatDouble(v); }

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
    // Unidentified, B is reported as 0; what bounds it is the curve's flattest point read by the
    // IEEE 952 slope method (min sigma / 0.664), so that bound must meet the limit.
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

struct Log {
  io::CsvTable table;
  double rate_hz = 1.0;
  std::vector<Eigen::Index> record_starts;  // gaps = split: where the log's records start
  std::vector<bool> logged;  // gaps = carry: the rows that were logged (empty: every row)
  std::vector<std::string> warnings;        // about its inputs (InputWarnings)
};

// What the user must know about a log's inputs: an assumed sample rate, temperature columns of
// the axes that do not look like degC (drift::TemperatureWarning), each naming the log's file.
std::vector<std::string> InputWarnings(const Manifest& m, const std::string& path,
                                       const io::CsvTable& table, const std::string& rate_how) {
  std::vector<std::string> out;
  const std::string name = fs::path(path).filename().string();
  if (rate_how == "default") {
    out.push_back(name +
                  ": no time_s column: its sample rate is taken as 1 Hz (set rate_hz in the "
                  "manifest if it is not)");
  }
  std::vector<std::string> seen;
  for (const AxisSpec& axis : m.axes) {
    for (const std::string& column : axis.temperature) {
      if (std::find(seen.begin(), seen.end(), column) != seen.end()) continue;
      seen.push_back(column);
      const std::string w = drift::TemperatureWarning(table.Column(column), column);
      if (!w.empty()) out.push_back(name + ": " + w);
    }
  }
  return out;
}

Log ReadUnitLog(const Manifest& m, const std::string& path) {
  Log log;
  log.table = io::ReadLog(path, m.log, nullptr,
                          m.log.gaps == io::GapPolicy::kSplit ? &log.record_starts : nullptr, {},
                          m.log.gaps == io::GapPolicy::kCarry ? &log.logged : nullptr);
  std::string how;
  log.rate_hz = io::ResolveSampleRate(log.table, m.rate_hz, &how);
  log.warnings = InputWarnings(m, path, log.table, how);
  return log;
}


Eigen::MatrixXd Temperatures(const io::CsvTable& table, const AxisSpec& axis) {
  Eigen::MatrixXd t(table.rows(), static_cast<Eigen::Index>(axis.temperature.size()));
  for (size_t c = 0; c < axis.temperature.size(); ++c) {
    t.col(static_cast<Eigen::Index>(c)) = table.Column(axis.temperature[c]);
  }
  return t;
}

std::string Joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

// Everything CalibrateUnit does, throwing on the unit's own errors.
UnitOutputs Calibrate(const Manifest& m, const UnitSpec& unit, const io::DygraphsAssets& assets) {
  UnitOutputs out;
  UnitResult& r = out.result;
  r.serial = unit.serial;

  std::vector<Log> cal;
  for (const std::string& path : unit.calibration) {
    cal.push_back(ReadUnitLog(m, path));
    io::RequireSameSampleRate(unit.calibration.front(), cal.front().rate_hz, path,
                              cal.back().rate_hz);
  }
  drift::DriftOptions options = m.FitOptions();
  options.features.rate_hz = cal.front().rate_hz;
  // Units run in parallel (RunFleet's threads, or one Dask task per worker thread), so a unit
  // runs on one thread: a decomposing method (ms-elm, emd-elm) would otherwise take every core
  // per unit, T units x every core on the machine, and a one-thread Dask worker would use them
  // all. The results do not depend on it: the model is the one `fit` writes with any --threads.
  const Execution one_thread{.threads = 1};
  std::vector<io::LoadedModel> models;
  for (const AxisSpec& axis : m.axes) {
    // The calibration logs one after the other: the target, then the temperatures.
    drift::RecordRows run;
    for (const Log& log : cal) {
      Eigen::MatrixXd block(log.table.rows(), 1 + static_cast<Eigen::Index>(axis.temperature.size()));
      block << log.table.Column(axis.target), Temperatures(log.table, axis);
      run.Append(block, log.record_starts, log.logged);
    }
    io::LoadedModel model;
    model.info.target_column = axis.target;
    model.info.temperature_column = Joined(axis.temperature);
    model.info.source = Joined(unit.calibration);
    model.info.rate_unit = std::string(allan::ToString(m.rate_unit));
    model.model = drift::FitDriftModel(run.rows.col(0), run.rows.rightCols(run.rows.cols() - 1),
                                       options, run.record_starts, one_thread, run.logged);
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
      }
      // A warning of the calibration report: the run could not identify this sub-model.
      a.identified = a.identified.value_or(true) && t.report.warnings.empty();
      for (const std::string& w : t.report.warnings) a.warnings.push_back(sub.name + ": " + w);
      for (const std::string& w : t.report.advice) a.warnings.push_back(sub.name + ": advice: " + w);
    }
    for (const Log& log : cal) {
      a.warnings.insert(a.warnings.end(), log.warnings.begin(), log.warnings.end());
    }
    r.axes.push_back(std::move(a));
    models.push_back(std::move(model));
  }
  out.files.push_back({"model.json", io::RenderModelFile(models)});

  std::vector<io::CsvColumn> allan_columns;
  for (size_t k = 0; k < unit.verification.size(); ++k) {
    const Log ver = ReadUnitLog(m, unit.verification[k]);
    // Block means and the Allan analysis of the verification need the time grid of a log with
    // no made-up rows; carry serves duty-cycled calibration logs.
    if (!ver.logged.empty()) {
      throw DataError(fmt::format(
          "{}: gaps = 'carry' fills this verification log's gaps ({} of {} rows made up), but the "
          "verification's block means and Allan deviation need logged rows: verify on a "
          "continuous log",
          unit.verification[k], ver.table.rows() - drift::CountLogged(ver.logged, ver.table.rows()),
          ver.table.rows()));
    }
    for (AxisResult& a : r.axes) {
      a.warnings.insert(a.warnings.end(), ver.warnings.begin(), ver.warnings.end());
    }
    std::vector<io::CsvColumn> columns;
    for (int c = 0; c < static_cast<int>(ver.table.header().size()); ++c) {
      columns.push_back({ver.table.header()[static_cast<size_t>(c)], ver.table.Column(c)});
    }
    const auto block = std::max<Eigen::Index>(
        1, static_cast<Eigen::Index>(std::llround(m.drift_window_s * ver.rate_hz)));
    for (size_t i = 0; i < m.axes.size(); ++i) {
      const AxisSpec& axis = m.axes[i];
      const drift::DriftModel& model = models[i].model;
      const Eigen::VectorXd y = ver.table.Column(axis.target);
      const Eigen::MatrixXd temperature = Temperatures(ver.table, axis);
      const Eigen::MatrixXd est_sd =
          drift::EstimateDriftWithSd(model, temperature, ver.record_starts);
      const Eigen::VectorXd estimate = est_sd.col(0);
      const Eigen::VectorXd compensated = y - estimate;
      const std::string suffix = m.axes.size() == 1 ? "" : "_" + axis.target;
      columns.push_back({"drift_est" + suffix, estimate});
      if (model.identified()) columns.push_back({"drift_sd" + suffix, est_sd.col(1)});
      columns.push_back({"compensated" + suffix, compensated});

      VerificationResult v;
      v.log = unit.verification[k];
      v.samples = y.size();
      v.rate_hz = ver.rate_hz;
      // The figures `gyrodrift compensate` reports, the slow variation over drift_window_s.
      const drift::CompensationSummary summary =
          drift::SummariseCompensation(y, compensated, ver.rate_hz, m.drift_window_s);
      v.mean_before = summary.before.mean;
      v.mean_after = summary.after.mean;
      v.std_before = summary.before.std;
      v.std_after = summary.after.std;
      v.output_means = drift::BlockMeans(y, block);
      v.compensated_means = drift::BlockMeans(compensated, block);
      v.estimate_means = drift::BlockMeans(estimate, block);
      v.block_hours.resize(v.output_means.size());
      for (Eigen::Index b = 0; b < v.block_hours.size(); ++b) {
        v.block_hours[b] = (static_cast<double>(b) + 0.5) * static_cast<double>(block) /
                           ver.rate_hz / 3600.0;
      }
      v.drift_rms_before = summary.before.slow;
      v.drift_rms_after = summary.after.slow;
      if (!axis.truth.empty()) {
        const Eigen::VectorXd truth = ver.table.Column(axis.truth);
        v.truth_means = drift::BlockMeans(truth, block);
        const double truth_rms = std::sqrt(truth.squaredNorm() / static_cast<double>(truth.size()));
        const double residual =
            std::sqrt((truth - estimate).squaredNorm() / static_cast<double>(truth.size()));
        v.truth_removed = truth_rms > 0.0 ? 1.0 - residual / truth_rms
                                          : std::numeric_limits<double>::quiet_NaN();
      }
      v.outside_share = drift::ShareOutsideRange(temperature.col(0), model.temperature_min_c,
                                                 model.temperature_max_c);
      // The Allan analysis needs uniform samples: of a log split at its gaps, its longest record.
      const auto [first, length] = LongestRecord(y.size(), ver.record_starts);
      v.noise_before =
          NoiseOf(y.segment(first, length), ver.rate_hz, m.rate_unit, &v.tau_s, &v.adev_before);
      Eigen::VectorXd tau_after;
      v.noise_after = NoiseOf(compensated.segment(first, length), ver.rate_hz, m.rate_unit,
                              &tau_after, &v.adev_after);
      v.failures = Failures(m.limits, v);
      // Every axis of one log has the same length, so the same taus.
      if (i == 0) allan_columns.push_back({fmt::format("tau_s_v{}", k + 1), v.tau_s});
      const std::string tag = fmt::format("{}_v{}", axis.target, k + 1);
      allan_columns.push_back({"adev_before_" + tag, v.adev_before});
      allan_columns.push_back({"adev_after_" + tag, v.adev_after});
      r.axes[i].verification.push_back(std::move(v));
    }
    out.files.push_back({fmt::format("verification_{}_compensated.csv", k + 1),
                         io::RenderCsv(columns)});
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

// A finished unit's rows from its summary.json when the fingerprint matches; false otherwise
// (missing, damaged, another fingerprint or another column set: the unit is redone).
bool ReadFinished(const std::string& path, const std::string& fingerprint,
                  std::vector<FleetRow>* rows) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    const json j = json::parse(io::ReadTextFile(path));
    if (j.at("fingerprint").get<std::string>() != fingerprint) return false;
    if (j.at("columns").get<std::vector<std::string>>() != FleetColumns()) return false;
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

int ColumnIndex(const std::string& name) {
  const auto& c = FleetColumns();
  return static_cast<int>(std::find(c.begin(), c.end(), name) - c.begin());
}

// Flags, per axis across the fleet, the rows whose figure lies more than 3.5 robust standard
// deviations (1.4826 MAD) from the fleet's median (Iglewicz & Hoaglin's modified z-score): a unit
// unlike its siblings deserves a look even when it passes its limits.
void FlagOutliers(std::vector<FleetRow>& rows) {
  const int axis_col = ColumnIndex("axis");
  const int outlier_col = ColumnIndex("outliers");
  for (const char* metric : {"drift_rms_after", "truth_removed", "bias_instability_after_dph",
                             "arw_after_dpsh", "bias"}) {
    const int col = ColumnIndex(metric);
    std::vector<std::string> axes;
    for (const FleetRow& r : rows) {
      const std::string& a = r.cells[static_cast<size_t>(axis_col)];
      if (!a.empty() && std::find(axes.begin(), axes.end(), a) == axes.end()) axes.push_back(a);
    }
    for (const std::string& axis : axes) {
      std::vector<std::pair<size_t, double>> values;
      for (size_t i = 0; i < rows.size(); ++i) {
        const auto& cells = rows[i].cells;
        if (cells[static_cast<size_t>(axis_col)] != axis) continue;
        const std::string& text = cells[static_cast<size_t>(col)];
        if (text.empty()) continue;
        const double v = std::strtod(text.c_str(), nullptr);
        if (std::isfinite(v)) values.push_back({i, v});
      }
      // Too few units to call one unusual. Units, not rows: a unit has a row per verification log.
      std::set<std::string> units;
      for (const auto& [i, v] : values) units.insert(rows[i].cells[0]);
      if (units.size() < 5) continue;
      std::vector<double> x;
      for (const auto& [i, v] : values) x.push_back(v);
      const double median = Median(x);
      std::vector<double> dev;
      for (double v : x) dev.push_back(std::abs(v - median));
      const double mad = 1.4826 * Median(dev);
      if (!(mad > 0.0)) continue;
      for (const auto& [i, v] : values) {
        if (std::abs(v - median) / mad <= 3.5) continue;
        std::string& flag = rows[i].cells[static_cast<size_t>(outlier_col)];
        flag += (flag.empty() ? "" : " ") + std::string(metric);
      }
    }
  }
}

}  // namespace

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
                          const io::DygraphsAssets& assets) {
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

const std::vector<std::string>& FleetColumns() {
  static const std::vector<std::string> kColumns = {
      "serial", "axis", "verification", "status", "failures", "outliers", "method", "samples",
      "std_before", "std_after", "drift_rms_before", "drift_rms_after", "drift_removed",
      "truth_removed", "arw_before_dpsh", "arw_after_dpsh", "bias_instability_before_dph",
      "bias_instability_after_dph", "rrw_before_dphpsh", "rrw_after_dphpsh", "bias", "cv_rmse",
      "skill", "regressors", "warnings", "identified", "outside_share", "mean_before",
      "mean_after", "unit_seconds"};
  return kColumns;
}

std::vector<FleetRow> Rows(const UnitResult& unit) {
  std::vector<FleetRow> rows;
  const std::string seconds = io::FormatDouble(unit.seconds);
  if (!unit.error.empty()) {
    FleetRow row;
    row.cells.assign(FleetColumns().size(), "");
    row.cells[0] = unit.serial;
    row.cells[3] = "error";
    row.cells[4] = unit.error;
    row.cells.back() = seconds;
    rows.push_back(std::move(row));
    return rows;
  }
  for (const AxisResult& a : unit.axes) {
    std::string regressors;
    for (const std::string& name : a.regressors) regressors += (regressors.empty() ? "" : "; ") + name;
    std::string warnings;
    for (const std::string& w : a.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
    for (const VerificationResult& v : a.verification) {
      std::string failures;
      for (const std::string& f : v.failures) failures += (failures.empty() ? "" : "; ") + f;
      const double drift_removed =
          v.drift_rms_before > 0.0 ? 1.0 - v.drift_rms_after / v.drift_rms_before
                                   : std::numeric_limits<double>::quiet_NaN();
      rows.push_back(FleetRow{{unit.serial,
                               a.target,
                               fs::path(v.log).filename().string(),
                               v.failures.empty() ? "pass" : "fail",
                               failures,
                               "",
                               a.model_summary.substr(0, a.model_summary.find(' ')),
                               std::to_string(v.samples),
                               Fmt(v.std_before),
                               Fmt(v.std_after),
                               Fmt(v.drift_rms_before),
                               Fmt(v.drift_rms_after),
                               Fmt(drift_removed),
                               Fmt(v.truth_removed),
                               Fmt(v.noise_before.n_dpsh.value),
                               Fmt(v.noise_after.n_dpsh.value),
                               Fmt(v.noise_before.b_dph.value),
                               Fmt(v.noise_after.b_dph.value),
                               Fmt(v.noise_before.k_dphpsh.value),
                               Fmt(v.noise_after.k_dphpsh.value),
                               Fmt(a.bias),
                               Fmt(a.cv_rmse),
                               Fmt(a.skill),
                               regressors,
                               warnings,
                               !a.identified ? "" : *a.identified ? "yes" : "no",
                               Fmt(v.outside_share),
                               Fmt(v.mean_before),
                               Fmt(v.mean_after),
                               seconds}});
    }
  }
  return rows;
}

std::string FleetResult::Summary() const {
  return fmt::format(
      "{} units: {} calibrated, {} skipped (done before), {} failed their limits, {} could not be "
      "calibrated; {:.1f} s ({:.2f} s per calibrated unit, median)",
      units, calibrated, skipped, failed_limits, errors, seconds, unit_seconds_median);
}

UnitRun RunUnit(const Manifest& m, const UnitSpec& unit, const std::string& output_dir,
                bool force, const io::DygraphsAssets& assets) {
  const std::string folder = (fs::path(output_dir) / unit.serial).string();
  const std::string summary = (fs::path(folder) / kSummaryFile).string();
  UnitRun run;
  std::string fingerprint;
  try {
    fingerprint = UnitFingerprint(m, unit);
  } catch (const Error& e) {
    UnitResult failed;
    failed.serial = unit.serial;
    failed.error = e.what();
    run.rows = Rows(failed);
    run.what = "error";
    return run;
  }
  if (!force && ReadFinished(summary, fingerprint, &run.rows)) {
    run.what = "skipped";
    return run;
  }
  UnitOutputs outputs = CalibrateUnit(m, unit, assets);
  run.rows = Rows(outputs.result);
  if (!outputs.result.error.empty()) {
    run.what = "error";
    return run;
  }
  json s = {{"fingerprint", fingerprint},
            {"serial", unit.serial},
            {"columns", FleetColumns()},
            {"rows", RowsJson(run.rows)}};
  std::vector<std::pair<std::string, std::string>> files;
  std::error_code ec;
  fs::create_directories(folder, ec);
  for (auto& [name, text] : outputs.files) {
    files.push_back({(fs::path(folder) / name).string(), std::move(text)});
  }
  files.push_back({summary, s.dump(1) + "\n"});
  try {
    io::WriteFilesAtomically(files);
    run.what = "calibrated";
    run.seconds = outputs.result.seconds;
  } catch (const Error& e) {
    outputs.result.error = e.what();
    run.rows = Rows(outputs.result);
    run.what = "error";
  }
  return run;
}

FleetResult FinishFleet(const Manifest& m, const std::string& output_dir,
                        const std::vector<UnitRun>& units, double seconds,
                        const io::DygraphsAssets& assets) {
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
  io::WriteFilesAtomically({{(fs::path(output_dir) / "fleet.csv").string(), csv},
                            {(fs::path(output_dir) / "fleet.html").string(),
                             RenderFleetReport(m, fleet, assets)}});
  return fleet;
}

FleetResult RunFleet(const Manifest& m, const FleetOptions& o, const FleetContext& context) {
  ValidateThreads(context.threads);
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  fs::create_directories(o.output_dir, ec);
  if (!fs::is_directory(o.output_dir, ec)) {
    throw IoError(o.output_dir + ": cannot create the output folder");
  }
  const io::DygraphsAssets assets = io::LoadDygraphs();
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
