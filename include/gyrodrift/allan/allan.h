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
//   IdentifyNoise(): fits quantization Q, angle random walk N, bias instability B, rate random
//   walk K and rate ramp R to an Allan-variance curve (IEEE Std 952-1997, Annex C) by least
//   squares in log variance, keeps the terms the curve needs by nested chi-square tests, and
//   reports the slope-method readings.
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
//   overlapping ADEV kernel is blocked over consecutive taus and vectorised), spread over
//   the execution's threads with ParallelFor; results are bit-identical for any thread count.
//   Octave grid: O(N log N); every averaging factor: O(N^2). Memory: about 3 N doubles.
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
  Eigen::Index n_samples = 0;      // input samples
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

// ---- Building blocks (exposed for tests and other modules) --------------------------------------

// Largest averaging factor the estimator accepts for n_phase phase points (at least one term;
// TOTDEV: (n_phase - 1) / 2).
std::int64_t MaxAveragingFactor(Deviation d, Eigen::Index n_phase);
// Number of terms of the estimator at averaging factor m.
std::int64_t TermCount(Deviation d, Eigen::Index n_phase, std::int64_t m);
// Averaging factors of a grid (sorted, unique, each <= MaxAveragingFactor).
std::vector<std::int64_t> AveragingFactors(const AllanOptions& options, Eigen::Index n_phase);

// Equivalent degrees of freedom of deviation `d` at factor m for n_phase points and noise alpha:
// Greenhall & Riley 2003 for ADEV/OADEV/MDEV/TDEV/HDEV/OHDEV, NIST SP 1065 table 7 for TOTDEV
// (alpha = 0, -1, -2; SP 1065 table 5 simple formulas for alpha = 2, 1, as Stable32).
double EquivalentDof(Deviation d, int alpha, std::int64_t m, Eigen::Index n_phase);
// Quantile of the chi-square distribution with `dof` (> 0, real) degrees of freedom.
double ChiSquareQuantile(double p, double dof);
// Regularized lower incomplete gamma P(a, x).
double RegularizedGammaP(double a, double x);
// [lo, hi] of a deviation with `edf` degrees of freedom at two-sided confidence `confidence`
// (NIST SP 1065 eq. 45).
void ConfidenceInterval(double dev, double edf, double confidence, double* lo, double* hi);

// Lag-1 autocorrelation noise identification (Riley & Greenhall 2004) at averaging factor m.
// `phase` is the internal phase (angle) series; for rate data the m-averaged rates are analysed,
// for angle data the m-decimated phase. dmax = 2 for Allan-type, 3 for Hadamard-type estimators.
// Returns nullopt when fewer than 30 points remain. Cost O(N / m), no copy of the series unless
// differencing is needed (rho >= 0.25 at d = 0).
std::optional<int> IdentifyAlpha(const Eigen::Ref<const Eigen::VectorXd>& phase, std::int64_t m,
                                 DataType type, int dmax);

// ---- IEEE 952 noise terms --------------------------------------------------------------------

struct NoiseFitOptions {
  // Fit only points with tau_min_s <= tau <= tau_max_s. Defaults: the whole curve.
  double tau_min_s = 0.0;
  double tau_max_s = std::numeric_limits<double>::infinity();
  // A term is kept only if, at some fitted tau, it carries at least this share of the fitted
  // model variance ("the taus where it matters"); terms below are set to 0 and refitted without.
  // Range [0, 1). Default 0.1.
  double min_share = 0.1;
  // Sample period tau0 (s) of a bare curve, used for the correlation between its points; 0 takes
  // the smallest fitted tau. IdentifyNoise(AllanResult) uses the result's own. Finite, >= 0.
  double sample_period_s = 0.0;
  // Level of the nested chi-square test (1 degree of freedom) that keeps a term: a term is
  // identified only if removing it from the selected model raises the misfit (corrected for the
  // correlation of the points) by more than the chi-square quantile 1 - significance (3.84 for
  // 0.05). A non-negative term that is truly absent passes about half as often (its null law is
  // half chi-square 0, half chi-square 1). Range (0, 0.5]. Default 0.05.
  double significance = 0.05;
  void Validate() const;
};

struct NoiseTerm {
  double value = 0.0;  // fitted value in the unit named below (0 if not identified)
  double sigma = 0.0;  // 1-sigma uncertainty (correlated points, see IdentifyNoise)
  double slope_reading = std::numeric_limits<double>::quiet_NaN();  // IEEE 952 slope method
  double slope_tau_s = std::numeric_limits<double>::quiet_NaN();    // tau of that reading
  bool identified = false;  // the selected model contains the term (see IdentifyNoise)
  double tau_lo_s = std::numeric_limits<double>::quiet_NaN();  // fitted taus where it matters
  double tau_hi_s = std::numeric_limits<double>::quiet_NaN();
  // Evidence for the term: identified, how much the misfit rises when it is removed from the
  // selected model; not identified, how much it falls when the term is added (0: the term would
  // fit at zero). In chi-square units: divided by the design effect of the correlated points and by
  // the larger model's reduced chi-square when that exceeds 1; compare with
  // NoiseTerms::critical_chi2. NaN if that model has more terms than points, or when the term is
  // the selected model's only one (the empty model is not fitted).
  double evidence_chi2 = std::numeric_limits<double>::quiet_NaN();
};

struct NoiseTerms {
  NoiseTerm q_urad;    // quantization Q, microradians (arcsec = urad * 0.206264806)
  NoiseTerm n_dpsh;    // angle random walk N, deg/sqrt(h)
  NoiseTerm b_dph;     // bias instability B, deg/h
  NoiseTerm k_dphpsh;  // rate random walk K, deg/h/sqrt(h)
  NoiseTerm r_dphph;   // rate ramp R, deg/h/h
  int points_used = 0;
  double tau_min_s = 0.0, tau_max_s = 0.0;  // fitted range actually used
  double chi2_per_dof = 0.0;   // log-variance misfit (independent points) / (points - terms)
  double critical_chi2 = 0.0;  // the test's critical value, chi-square quantile 1 - significance
  double min_dev_dph = 0.0, min_dev_tau_s = 0.0;  // minimum of the curve (deg/h)
  std::string Summary() const;
  // Model Allan deviation in deg/h at tau from the fitted terms.
  double ModelDevDph(double tau_s) const;
};

// Fits the IEEE 952 model sigma^2 = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
// to an ADEV, OADEV or TOTDEV curve (UsageError for other estimators). Each point's AVAR estimate
// is taken as AVAR chi2_edf / edf (EDF from the result when available, else n_terms), so its
// logarithm has a known mean offset and variance; the terms' squares (non-negative) are fitted to
// the log variances by least squares. Every subset of the five terms is fitted; the reported model
// is found by removing terms, steepest first (R, Q, K, N, then B), while a nested chi-square test
// at options.significance finds them unnecessary or they carry less than min_share of the model
// everywhere. The correlation of neighbouring points (avar_correlation.h in src/allan; exact for
// OADEV in long records, an approximation for ADEV and TOTDEV) enters the tests (design effect)
// and the uncertainties (sandwich covariance); both are widened by the reduced chi-square when
// that exceeds 1. Uncertainties are those of the selected model (docs/allan.md section 3 gives
// their coverage, and where a term absorbs one the record cannot separate from it). Points closer
// than a factor sqrt(2) in tau are thinned to the first.
// Cost: 31 small fits and one correlation matrix (about 4e4 x T^2) for T points: 11 ms for 19.
NoiseTerms IdentifyNoise(const AllanResult& result, const NoiseFitOptions& options = {});
// Same from a bare curve: tau (s), Allan deviation in deg/h and EDF per point.
NoiseTerms IdentifyNoise(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                         const Eigen::VectorXd& edf, const NoiseFitOptions& options = {});

}  // namespace gyrodrift::allan
