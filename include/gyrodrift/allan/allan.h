// Allan-variance family of a gyro record, with confidence intervals, and IEEE Std 952 noise
// identification.
//
// What it computes
//   Compute(): ADEV, overlapping ADEV, modified ADEV, Hadamard, overlapping Hadamard, time
//   deviation and total deviation at a grid of averaging times tau = m * tau0, for rate data
//   (a gyro's deg/h output; "frequency-type" in the time-and-frequency literature) or angle data
//   ("phase-type"). Every point carries its number of terms, the noise type identified at that tau
//   (lag-1 autocorrelation, Riley & Greenhall 2004), the equivalent degrees of freedom and the
//   chi-square confidence interval.
//   The equivalent degrees of freedom and the confidence intervals are in edf.h; the IEEE Std
//   952 noise terms fitted to a curve (IdentifyNoise) in noise_fit.h.
//
// References
//   W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065 (2008): estimators,
//     term counts, TOTDEV reflection, EDF of TOTDEV (table 7), chi-square intervals (eq. 45).
//   C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
//     differences", 35th PTTI (2003): EDF of ADEV/OADEV/MDEV/TDEV/HDEV/OHDEV.
//   W. J. Riley, C. A. Greenhall, "Power law noise identification using the lag 1
//     autocorrelation", EFTF 2004.
//   IEEE Std 952-1997, Annex C (Allan variance of FOG noise terms).
//
// Units
//   Rate data are in the unit named by AllanOptions::units (deg/h by default); angle data are in
//   degrees for deg/h and deg/s, radians for rad/s. Deviations come back in that rate unit (TDEV in
//   rate unit x seconds, i.e. deg/h*s for deg/h). Averaging times are in seconds.
//
// Cost
//   O(N) to integrate, then O(N) per averaging time for every estimator (running sums; the
//   overlapping ADEV kernel sweeps the phase once for all its taus, vectorised; the noise
//   identification twice for all taus), spread over the execution's threads with ParallelFor;
//   results are bit-identical for any thread count. Octave grid: O(N log N); every averaging
//   factor: O(N^2). Memory: the phase, N + 1 doubles (none beyond the samples when they are
//   handed over); TOTDEV 3 N more; noise identification of strongly correlated data up to N more.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"

namespace gyrodrift::allan {

// Which estimator.
enum class Deviation {
  kAdev,    // non-overlapping Allan deviation
  kOadev,   // overlapping Allan deviation (the IEEE 952 curve; the default)
  kMdev,    // modified Allan deviation
  kHdev,    // non-overlapping Hadamard deviation
  kOhdev,   // overlapping Hadamard deviation
  kTdev,    // time deviation, tau / sqrt(3) * MDEV, in rate unit x s
  kTotdev,  // total deviation (phase reflected at both ends, NIST SP 1065 sec. 5.2.11)
};
std::string ToString(Deviation d);                  // "adev", "oadev", ...
Deviation DeviationFromString(std::string_view s);  // throws UsageError

enum class DataType {
  kRate,   // samples are rates (frequency-type data); integrated to angle internally
  kAngle,  // samples are accumulated angles (phase-type data)
};
std::string ToString(DataType t);  // "rate", "angle"
DataType DataTypeFromString(std::string_view s);

enum class RateUnit {
  kDegPerHour,    // "dph"
  kDegPerSecond,  // "dps"
  kRadPerSecond,  // "rads"
};
std::string ToString(RateUnit u);
RateUnit RateUnitFromString(std::string_view s);
// Factor that converts a rate in `u` to deg/h.
double ToDegPerHour(RateUnit u);

enum class TauGrid {
  kAll,     // every averaging factor m = 1, 2, 3, ... up to the estimator's limit
  kOctave,  // m = 1, 2, 4, 8, ...
  kDecade,  // m = 1, 2, 4, 10, 20, 40, 100, ... (the Stable32 decade grid)
  kList,    // the averaging times in AllanOptions::tau_list_s
};
std::string ToString(TauGrid g);
TauGrid TauGridFromString(std::string_view s);

// Noise types by the exponent alpha of the rate (frequency) PSD, S_y(f) ~ f^alpha:
// +2 white phase (angle) noise / quantization, +1 flicker phase, 0 white rate (ARW),
// -1 flicker rate (bias instability), -2 random-walk rate (RRW); -3, -4 for Hadamard only.
std::string NoiseTypeName(int alpha);

struct AllanOptions {
  // Sample rate of the record in Hz; tau0 = 1 / rate_hz. Range: finite, > 0. Default 1.
  double rate_hz = 1.0;
  // Rate samples (default) or angle samples.
  DataType data_type = DataType::kRate;
  Deviation deviation = Deviation::kOadev;
  TauGrid grid = TauGrid::kOctave;
  // Averaging times in s for TauGrid::kList; each is rounded to the nearest multiple of tau0
  // (at least tau0), duplicates dropped, sorted. Every value must be finite and > 0.
  std::vector<double> tau_list_s = {};
  // Unit of rate samples (and of the returned deviation). Default deg/h.
  RateUnit units = RateUnit::kDegPerHour;
  // Two-sided confidence level of [dev_lo, dev_hi]. Range (0, 1). Default 0.683 (1 sigma, the
  // Stable32 convention).
  double confidence = 0.683;
  // Compute noise identification, EDF and confidence intervals (costs a little; off gives NaN
  // bounds). Default on.
  bool confidence_intervals = true;
  // Force the noise type used for the EDF instead of identifying it per tau (alpha in -4..2, see
  // NoiseTypeName); empty = identify (default).
  std::optional<int> forced_alpha = {};

  double tau0_s() const { return 1.0 / rate_hz; }
  // Throws UsageError "<field> = <value>: must be <rule>".
  void Validate() const;
  bool operator==(const AllanOptions&) const = default;
};

struct AllanPoint {
  double tau_s = 0.0;
  std::int64_t m = 0;        // averaging factor, tau = m * tau0
  double dev = 0.0;          // deviation in the rate unit (TDEV: rate unit x s)
  double dev_lo = 0.0;       // lower confidence bound (NaN if intervals are off)
  double dev_hi = 0.0;       // upper confidence bound
  std::int64_t n_terms = 0;  // number of terms in the estimator's sum (Stable32 "#")
  double edf = 0.0;          // equivalent degrees of freedom (NaN if intervals are off)
  int alpha = 0;             // noise type used for the EDF (identified or forced)
  bool alpha_identified =
      false;  // false: carried over from a neighbouring tau (< 30 points) or forced
};

struct AllanResult {
  AllanOptions options;
  Eigen::Index n_samples = 0;      // input samples (with gaps: the made-up and breaks too)
  Eigen::Index n_logged = -1;      // of them logged (ComputeWithGaps), -1: every one
  Eigen::Index n_phase = 0;        // angle (phase) points the estimators see (rate: n_samples + 1)
  std::vector<AllanPoint> points;  // increasing tau

  Eigen::VectorXd tau_s() const;
  Eigen::VectorXd dev() const;
  // e.g. "oadev of 1000000 rate samples at 100 Hz: 20 taus 0.01..5243 s, min 0.0123 dph at 81.9 s"
  std::string Summary() const;
};

// Runs the estimator on `data` (rate or angle samples, see options) on execution.threads workers
// (its progress is not called). Throws UsageError for bad options or threads and DataError for
// non-finite samples or a record too short for the requested taus (at least one tau must be
// computable; list taus beyond the estimator's limit are an error).
AllanResult Compute(const Eigen::VectorXd& data, const AllanOptions& options,
                    const Execution& execution = {});
// The same on samples handed over (std::move): the phase is built in their storage, so the call
// needs no second copy of the record (at 1e8 samples, 800 MB less at the peak). `data` is
// consumed whether or not the call succeeds.
AllanResult Compute(Eigen::VectorXd&& data, const AllanOptions& options,
                    const Execution& execution = {});

// A record with gaps (a duty-cycled or interrupted log) on its uniform time grid: `logged` holds
// one flag per sample, false where the sample was made up (io::GapPolicy::kCarry) or is a break
// between records; the made-up values are never used. The overlapping estimators (oadev, ohdev;
// rate data) then sum only the cluster pairs (triples) whose 2m (3m) samples are all logged, as
// allantools does with NaN gaps, and divide by how many there are: n_terms counts them, a tau
// without one is left out, and the EDF is that of a gap-free record giving as many terms (an
// approximation: the terms of a gapped record are less correlated, so the interval is wider than
// it need be). The noise type per tau is identified on the longest run of logged samples. With
// every flag set it gives Compute's values (to rounding: a plain sum, not Compute's blocked one). Throws UsageError for another estimator or angle data,
// DataError when the mask does not match the data or no tau has a term (naming the longest run).
AllanResult ComputeWithGaps(const Eigen::VectorXd& data, const std::vector<bool>& logged,
                            const AllanOptions& options, const Execution& execution = {});

// ---- Building blocks (exposed for tests and other modules) --------------------------------------

// Largest averaging factor the estimator accepts for n_phase phase points (at least one term;
// TOTDEV: (n_phase - 1) / 2).
std::int64_t MaxAveragingFactor(Deviation d, Eigen::Index n_phase);
// Number of terms of the estimator at averaging factor m.
std::int64_t TermCount(Deviation d, Eigen::Index n_phase, std::int64_t m);
// Averaging factors of a grid (sorted, unique, each <= MaxAveragingFactor).
std::vector<std::int64_t> AveragingFactors(const AllanOptions& options, Eigen::Index n_phase);


}  // namespace gyrodrift::allan
