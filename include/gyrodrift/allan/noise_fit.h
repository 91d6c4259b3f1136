// IEEE Std 952 noise terms of a gyro from its Allan-variance curve: quantization Q, angle random
// walk N, bias instability B, rate random walk K and rate ramp R (IEEE Std 952-1997, Annex C),
// fitted by least squares in log variance, the terms the curve needs kept by nested chi-square
// tests, with the slope-method readings beside them.
//
// Units: Q in microradians, N in deg/sqrt(h), B in deg/h, K in deg/h/sqrt(h), R in deg/h/h; taus
// in seconds.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "gyrodrift/allan/allan.h"

namespace gyrodrift::allan {

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

// A reduced chi-square above this is a curve outside the five-term shape, not scatter: fits of
// the five terms to their own curves give about 1 (docs/allan.md 4-5), the real FOG curves fitted
// below 1 s, where they carry the sensors' filtering, hundreds.
inline constexpr double kMisfitNote = 10.0;

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
  // What the user should know about the fit ("" for none): a misfit the five terms cannot explain
  // (chi2_per_dof above kMisfitNote), which a narrower fitted range usually cures, or too few
  // points to tell the terms apart (five or fewer).
  std::string note;
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
// Same from a bare curve: tau (s), Allan deviation in deg/h and EDF per point (DataError for a tau
// or an EDF that is not a finite number > 0; points without a positive deviation are passed over).
NoiseTerms IdentifyNoise(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                         const Eigen::VectorXd& edf, const NoiseFitOptions& options = {});

}  // namespace gyrodrift::allan
