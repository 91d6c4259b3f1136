// Thermal calibration of a fleet of gyros (gyrodrift calibrate, docs/calibration.md).
//
// Per unit and axis: fit the compensate-mode drift model on the calibration log (exactly what
// `gyrodrift fit --target <every axis> --mode compensate` writes, seed and options alike),
// compensate each verification log, and measure before and after compensation:
//   - the mean (the bias the compensation moves) and the standard deviation;
//   - the residual drift: RMS, about their mean, of the output's means over drift_window_s
//     blocks (the slow part the compensation is for; white noise averages out of it), as
//     drift::SummariseCompensation computes it for `gyrodrift compensate`;
//   - the Allan deviation (overlapping, octave taus) and its IEEE 952 terms N, B, K;
//   - with a true-drift column: the share of its RMS removed, 1 - RMS(truth - estimate) /
//     RMS(truth), as `compensate --truth` reports it;
// then pass/fail against the manifest's limits (every verification log must pass).
//
// Units run in parallel (ParallelFor over the FleetContext's threads, each unit single-threaded
// inside, so results do not depend on the thread count). Each unit's files are written together,
// atomically, into OUT/<serial>/ with summary.json last in the set; a rerun skips a unit whose
// summary.json holds the same fingerprint (manifest settings and the logs' bytes: UnitFingerprint)
// and whose files are as written (summary.json keeps their hashes) unless `force`. The manifest
// and the logs must lie outside OUT (UsageError). A unit that fails (unreadable log, a fit that
// cannot run) is reported with its one-line error and the others go on. OUT/fleet.csv (one row per
// unit, axis and verification log) and OUT/fleet.html (distributions across the fleet, outliers
// flagged, units whose calibration could not identify their model marked, links to each unit's
// page) are written at the end.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/fleet/manifest.h"
#include "gyrodrift/html/report.h"

namespace gyrodrift::fleet {

// One verification log of one axis.
struct VerificationResult {
  std::string log;  // path from the manifest's folder (PathFromManifest)
  Eigen::Index samples = 0;
  double rate_hz = 0.0;
  double mean_before = 0.0, mean_after = 0.0;              // rate unit: the bias moved
  double std_before = 0.0, std_after = 0.0;                // rate unit
  // Rate unit: drift::SummariseCompensation's slow variation over drift_window_s blocks (NaN for
  // a log shorter than two blocks: not measured, so a residual drift limit is broken).
  double drift_rms_before = 0.0, drift_rms_after = 0.0;
  double truth_removed = std::numeric_limits<double>::quiet_NaN();  // share, NaN: no truth
  double outside_share = 0.0;  // samples beyond the calibration's temperature range
  allan::NoiseTerms noise_before, noise_after;
  Eigen::VectorXd tau_s, adev_before, adev_after;  // rate unit
  // Series for the unit's report, drift_window_s block means (x in hours).
  Eigen::VectorXd block_hours, output_means, compensated_means, estimate_means, truth_means;
  std::vector<std::string> failures;  // limits this log breaks, one phrase each
};

struct AxisResult {
  std::string target;
  std::string temperature;  // columns, comma-separated
  std::string model_summary;
  std::vector<std::string> regressors;  // the identified model's regressor names (thermal)
  double bias = std::numeric_limits<double>::quiet_NaN();  // intercept, rate unit (thermal)
  double cv_rmse = std::numeric_limits<double>::quiet_NaN();
  double skill = std::numeric_limits<double>::quiet_NaN();
  // The autopilot form fitted beside a one-sub-model thermal model (drift::AutopilotForm: what
  // export --format px4 writes): its summary ("" when none) and the share of the slow drift the
  // full model removes that it keeps (NaN: not measured).
  std::string autopilot;
  double autopilot_kept = std::numeric_limits<double>::quiet_NaN();
  // The calibration-run warnings of its thermal sub-models ("<sub-model>: ..."), then those on
  // its logs' inputs ("<log file>: ...": an assumed sample rate, a temperature that does not
  // look like degC).
  std::vector<std::string> warnings;
  // Whether the calibration run identified the model: false when a thermal sub-model's
  // calibration report has warnings (it says what the run could not identify, or that the model
  // fell back to a constant); unset for a method without identified thermal sub-models.
  std::optional<bool> identified;
  std::vector<VerificationResult> verification;
  bool pass() const;
};

struct UnitResult {
  std::string serial;
  std::string error;  // "" = calibrated; else the one-line error
  std::vector<AxisResult> axes;
  double seconds = 0.0;  // wall time of this unit
  bool pass() const;
};

// The result of one unit and the files to write into its folder (names relative to it; the
// model file, the compensated logs, the Allan table, report.html, summary.json).
struct UnitOutputs {
  UnitResult result;
  std::vector<std::pair<std::string, std::string>> files;
};

// Calibrates one unit (never throws for the unit's own data: the error goes into result.error and
// files is empty). `assets` inline dygraphs into the report.
UnitOutputs CalibrateUnit(const Manifest& manifest, const UnitSpec& unit,
                          const html::DygraphsAssets& assets);

// One row of fleet.csv: unit, axis, verification log and every figure above, as text.
struct FleetRow {
  std::vector<std::string> cells;  // FleetColumns() order
};
const std::vector<std::string>& FleetColumns();
std::vector<FleetRow> Rows(const UnitResult& unit);

struct FleetOptions {
  std::string output_dir;  // created if missing
  bool force = false;      // redo units whose summary.json matches
  bool operator==(const FleetOptions&) const = default;
};

// How RunFleet runs; nothing here changes a file it writes (but the timings).
struct FleetContext {
  int threads = 0;  // units at once, in [0, 1024]; 0 (default) = every core
  // Called after each unit, never concurrently (from the worker that finished it): units done,
  // total, serial, "calibrated" / "skipped" / "error". May be empty (default); throw from it to
  // stop the fleet (the units already written stay).
  std::function<void(int done, int total, const std::string& serial, const std::string& what)>
      progress = {};
};

struct FleetResult {
  std::vector<FleetRow> rows;  // every unit's rows, in manifest order
  int units = 0, calibrated = 0, skipped = 0, errors = 0, failed_limits = 0;
  double seconds = 0.0;
  double unit_seconds_median = 0.0;  // of the units calibrated in this run
  bool all_pass() const { return errors == 0 && failed_limits == 0; }
  std::string Summary() const;  // one line
};

// One unit's part of RunFleet, shared with callers that spread units over other workers (the
// Python package's Dask runner): calibrates `unit` into output_dir/<serial>/ (its files written
// together, atomically, summary.json last) unless that summary.json holds the unit's fingerprint
// and !force. Never throws for the unit's own data: errors become rows.
struct UnitRun {
  std::vector<FleetRow> rows;
  std::string what;      // "calibrated", "skipped" or "error"
  double seconds = -1.0;  // wall time when calibrated in this run, else -1
};
UnitRun RunUnit(const Manifest& manifest, const UnitSpec& unit, const std::string& output_dir,
                bool force, const html::DygraphsAssets& assets);

// UsageError unless the manifest and the logs of `unit` (of every unit when null) lie outside
// `output_dir`: a unit's files, or fleet.csv, would otherwise overwrite a log. RunFleet and RunUnit
// check it; a scheduler of units checks it once before it starts any.
void RequireInputsOutside(const Manifest& manifest, const UnitSpec* unit,
                          const std::string& output_dir);

// The end of RunFleet: the totals of every unit's run (manifest order, one per unit; UsageError
// otherwise), outliers flagged, and output_dir/fleet.csv and fleet.html written. `seconds` is the
// fleet's wall time as the caller measured it.
FleetResult FinishFleet(const Manifest& manifest, const std::string& output_dir,
                        const std::vector<UnitRun>& units, double seconds,
                        const html::DygraphsAssets& assets);

// Calibrates every unit of the manifest into options.output_dir (see the header comment).
// Throws UsageError / IoError for the fleet as a whole (no output folder, no dygraphs, threads
// out of range); a unit's own failure is a row, not an exception.
FleetResult RunFleet(const Manifest& manifest, const FleetOptions& options,
                     const FleetContext& context = {});

// The fleet report from fleet.csv's rows: a summary, the distributions of the residual drift, the
// share removed, the bias and the noise terms across units, the rows with outliers flagged and a
// link to each unit's report.
std::string RenderFleetReport(const Manifest& manifest, const FleetResult& fleet,
                              const html::DygraphsAssets& assets);

}  // namespace gyrodrift::fleet
