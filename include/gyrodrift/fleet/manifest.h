// The calibration manifest of a fleet of gyros: which units, their calibration and verification
// logs, the axes (gyro column, temperature column(s), optional true-drift column), the method and
// the pass/fail limits. TOML (toml.io), parsed with toml++ (Debian libtomlplusplus-dev).
//
//   method = "thermal"            # fit --method of every axis (compensate mode); default thermal
//   rate_unit = "dph"             # unit of the gyro columns: dph | dps | rads (allan --units)
//   rate_hz = 1.0                 # optional; default: from each log's time_s, else 1 Hz
//   gaps = "error"                # optional: error | interpolate | split | carry (io::GapPolicy;
//                                 # split: the thermal method only; carry: a method without a
//                                 # decomposition, and calibration logs only: a verification
//                                 # log with made-up rows is refused)
//   delimiter = "auto"            # optional: auto | comma | tab | semicolon (io::Delimiter)
//   names = ["t", "gx"]           # optional, and every other io::LogOptions field as its key
//   skip_rows = 0                 # (tasks::LogOptionsFromJson: names, skip_rows, bad_lines,
//   bad_lines = "error"           # ulog_topic, ulog_axes, ulog_temperature, ulog_units,
//                                 # ulog_instance), as the flags of the same names
//   seed = 1                      # optional, and every other fit setting as its key
//   nonlinear = false             # (drift::FitSettings through tasks::FitSettingsFromJson:
//   hysteresis = "auto"           # decomposition, hidden, thermal_features, time_constants,
//                                 # ensemble, realisations, seed, nonlinear, hysteresis, ...), as
//                                 # fit's flags of the same names; not mode (compensate),
//                                 # threads (calibrate --threads) or rate_hz (the fleet's key)
//   reference_temperature_c = 20  # optional: the setting reference_temperature, with its unit
//   drift_window_s = 100          # optional: residual drift = RMS of block means this long
//
//   [limits]                      # optional; a limit left out is not checked
//   residual_drift_rms = 0.02     # compensated verification output, rate unit
//   bias_instability_dph = 0.05   # IEEE 952 B of the compensated output, deg/h
//   removed_share_min = 0.8       # of the true drift (needs `truth`), in [0, 1]
//
//   [[axis]]                      # one per gyro axis, in the model file's order
//   target = "gyro_x"
//   temperature = ["temp_x"]      # one column or several
//   truth = "drift_x"             # optional: column of the true drift in the verification logs
//
//   [[unit]]
//   serial = "FOG-0001"
//   calibration = "FOG-0001/cal.csv"          # relative paths are relative to the manifest;
//                                             # several runs fitted together: the thermal method
//   verification = ["FOG-0001/ver.csv"]       # one or several
//
// Every key is checked: an unknown key (a misspelt limit would silently go unchecked), a wrong
// type, a value out of range, a repeated serial or axis, a log that does not exist or lacks a
// column, all throw UsageError "MANIFEST:LINE: ..." naming the line, before any unit is fitted.
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/io/gyro_log.h"

namespace gyrodrift::fleet {

inline constexpr double kNoLimit = std::numeric_limits<double>::quiet_NaN();

struct Limits {
  double residual_drift_rms = kNoLimit;    // rate unit, >= 0
  double bias_instability_dph = kNoLimit;  // deg/h, >= 0
  double removed_share_min = kNoLimit;     // in [0, 1]
  bool operator==(const Limits&) const = default;
};

struct AxisSpec {
  std::string target = {};                    // gyro output column
  std::vector<std::string> temperature = {};  // temperature column(s), degC
  std::string truth = {};                     // "" = none
  int line = 0;                          // in the manifest
};

// The files a fleet run writes into its output folder beside the units' folders (named by their
// serials): no serial may be one of them.
inline constexpr const char* kFleetTableFile = "fleet.csv";
inline constexpr const char* kFleetReportFile = "fleet.html";

struct UnitSpec {
  std::vector<std::string> Logs() const;  // calibration, then verification
  std::string serial;
  std::vector<std::string> calibration;   // resolved paths, fitted as records of one run
  std::vector<std::string> verification;  // resolved paths
  int line = 0;
  // As the manifest names them: the model file's training.source, the same whichever folder or
  // runner (calibrate, Python, Dask) the run starts from. Empty (a spec built in code): the
  // resolved paths.
  std::vector<std::string> calibration_as_written;
};

struct Manifest {
  std::string path;  // the manifest file
  allan::RateUnit rate_unit = allan::RateUnit::kDegPerHour;
  double rate_hz = 0.0;  // 0 = from each log
  io::LogOptions log;  // how every log is read (every field a key)
  // How every axis is fitted (every field a key but those the fleet sets: compensate mode, a
  // temperature, calibrate's threads, the sample rate of each log).
  drift::FitSettings fit{.mode = "compensate", .method = "thermal", .has_temperature = true};
  double drift_window_s = 100.0;  // in [1, 1e5]
  Limits limits;
  std::vector<AxisSpec> axes;  // 1 to io::kMaxModelAxes
  std::vector<UnitSpec> units;  // at least one

  // The drift options every axis is fitted with (drift::MakeDriftOptions of `fit`, as fit's
  // flags); rate_hz is settled per log.
  drift::DriftOptions FitOptions() const;
  // The method `fit` names ("auto": thermal).
  drift::Method FitMethod() const;
};

// Parses a manifest's text; `path` names it in messages and anchors relative log paths. Checks
// the keys, types and ranges and that the logs exist (not their columns: CheckLogColumns).
// Throws UsageError "PATH:LINE: ...".
Manifest ParseManifest(const std::string& text, const std::string& path);
// Reads and parses; IoError when the file cannot be read.
Manifest ReadManifest(const std::string& path);

// Reads the header of every log of every unit and throws UsageError "PATH:LINE: ..." (the unit's
// line) naming the first missing axis, temperature or truth column.
void CheckLogColumns(const Manifest& manifest);

// A unit's fingerprint: FNV-1a 64 of FingerprintJson's text, so a rerun redoes a unit whose logs
// or settings changed and skips one that is done. FingerprintJson: the settings' JSON with its
// version (tasks::SettingsToJson: every fit and log setting, so a setting added there is in the
// fingerprint too), the fleet's own keys (rate_unit, rate_hz, drift_window_s, limits, axes) and
// the unit (serial, number of calibration logs, each log's path and FNV-1a 64 of its bytes).
// Before this form (2026-11, issue 25) the fingerprint hashed a hand-made list of some of these;
// a summary.json of that form never matches, so each unit is calibrated once more.
// A log's path from the manifest's folder: the same however the manifest was named and from
// whichever folder or front end the run started (the path as given when it cannot be resolved).
std::string PathFromManifest(const Manifest& manifest, const std::string& log);

nlohmann::json FingerprintJson(const Manifest& manifest, const UnitSpec& unit);
std::string UnitFingerprint(const Manifest& manifest, const UnitSpec& unit);

}  // namespace gyrodrift::fleet
