// The `allan` user operation, written once for every front end (issue 25): settings by name as a
// user gives them, their one mapping onto allan::AllanOptions and NoiseFitOptions, the rule that
// the IEEE 952 noise terms need an Allan-variance curve (an OADEV on the same grid is fitted for
// the other estimators), and the record the sidecar writes. `gyrodrift allan` and the Python
// package's `allan` call RunAllan and nothing below it.
//
// Units: rates in `units`, taus in s, the noise terms in deg/h-based units (noise_fit.h).
// Cost: one or two allan::Compute of the record (noise_fit.h for the fit).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/execution.h"

namespace gyrodrift::tasks {

// Every setting of the operation, its default and its range: the one home of each (the CLI's flag
// defaults and the Python keyword defaults are read from a default-constructed AllanSettings).
struct AllanSettings {
  double rate_hz = 0.0;       // sample rate, Hz, in [1e-9, 1e9] (required: 0 is refused)
  std::string type = "rate";  // allan::DataType name: rate (gyro output) | angle (integrated)
  std::string dev = "oadev";  // allan::Deviation name: oadev|adev|mdev|hdev|ohdev|tdev|totdev
  // The taus: all | octave | decade | comma-separated taus in s, each a whole number of sample
  // periods. Ignored when tau_list_s is not empty.
  std::string taus = "octave";
  std::vector<double> tau_list_s = {};  // taus in s (the Python package's sequence form)
  std::string units = "dph";            // allan::RateUnit name: dph | dps | rads
  double confidence = 0.683;            // two-sided confidence of the bounds, in (0, 1 - 1e-12]
  int threads = 0;                      // worker threads, in [0, 1024]; 0 = every core
  double fit_tau_min_s = 0.0;           // noise fit: smallest tau, s
  double fit_tau_max_s = std::numeric_limits<double>::infinity();  // noise fit: largest tau, s

  // The options of these settings, validated; throws OptionError naming the setting (rate_hz,
  // taus, confidence, tau_min_s, ...) or UsageError (an unknown name).
  allan::AllanOptions Options() const;
  allan::NoiseFitOptions FitOptions() const;
  Execution MakeExecution() const;
  // Every check of the three above, before any data is read.
  void Validate() const;
};

// What the operation computed.
struct AllanRun {
  allan::AllanResult curve;                // the asked deviation
  std::optional<allan::NoiseTerms> terms;  // nullopt when the curve has too few points to fit
  std::string fit_source;                  // the deviation the terms were fitted to
  std::string fit_error;                   // why the terms are missing, else empty
  std::string dev_unit;                    // of curve.points[].dev ("dph", "dph*s" for tdev)
};

// The deviation of `data` (in settings.units) and its noise terms. `logged`: empty, or one flag
// per sample, false where the sample is missing (allan::ComputeWithGaps). The samples are taken
// by value: handed over (std::move), their last use builds the phase in their storage (no second
// copy of the record, allan::Compute). Throws what AllanSettings::Validate and allan::Compute
// throw, and a DataError naming `signal_name` for constant data (its deviation is zero at every
// tau); a fit with too few points is reported in fit_error, not thrown.
AllanRun RunAllan(Eigen::VectorXd data, const std::vector<bool>& logged,
                  const AllanSettings& settings, std::string_view signal_name = "x");

// Records (a log split at its gaps: `record_starts`, the first sample of every record after the
// first, increasing, inside 1..size-1) analysed on one grid: joined with one missing sample between
// them, *logged (empty going in: records, or a mask, not both) marking it (allan::ComputeWithGaps),
// so no cluster pair spans a break. Throws DataError for starts out of order or out of range,
// UsageError for a mask given.
Eigen::VectorXd JoinRecords(const Eigen::VectorXd& data,
                            const std::vector<Eigen::Index>& record_starts,
                            std::vector<bool>* logged);

// The records the sidecar writes (docs/allan.md): the noise terms (the keys of `noise_terms`
// without source_dev and method), and the whole analysis: options (the settings with the tau grid
// they resolve to), samples, logged_samples and gaps_method (with `logged`), summary, dev_unit,
// edf_method, points, noise_terms ({"error": ...} when not fitted).
nlohmann::json NoiseTermsRecord(const allan::NoiseTerms& terms);
nlohmann::json AllanRecord(const AllanRun& run, const AllanSettings& settings,
                           const std::vector<bool>& logged);

}  // namespace gyrodrift::tasks
