// IEEE Std 952 noise terms from an Allan-variance curve (noise_fit.h). The fits live in
// noise_subset_fits.cc, the choice of terms in noise_model_selection.cc; this file gathers the
// points, runs both and reports the terms beside the slope-method readings.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

#include "allan/avar_correlation.h"
#include "allan/noise_model_selection.h"
#include "allan/noise_subset_fits.h"
#include "allan/noise_terms_model.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/edf.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::allan {
namespace {

using internal::Column;
using internal::Evidence;
using internal::kAllTerms;
using internal::kBiasFactor;
using internal::kTerms;
using internal::NnlsFit;
using internal::SubsetFits;
using internal::TermAt;
using internal::TermsOf;
using internal::ToReportUnit;

// Slope-method readings (IEEE 952 Annex C): at the point whose local log-log slope is closest to
// the term's slope (within 0.25), sigma = sqrt(col_j(tau)) * term. Only points whose slope rests
// on usable neighbours (EDF >= 5, about +-32 % per point) are read, so the noisy tail
// of a curve does not produce readings.
void SlopeReadings(const Eigen::VectorXd& tau, const Eigen::VectorXd& adev,
                   const Eigen::VectorXd& edf, NoiseTerms* out) {
  constexpr double kMinEdf = 5.0;
  const Eigen::Index n = tau.size();
  if (n < 2) return;
  Eigen::VectorXd slope(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index a = std::max<Eigen::Index>(0, i - 1), b = std::min(n - 1, i + 1);
    slope[i] = std::log(adev[b] / adev[a]) / std::log(tau[b] / tau[a]);
  }
  constexpr std::array<double, kTerms> kSlope{-1.0, -0.5, 0.0, 0.5, 1.0};
  for (int j = 0; j < kTerms; ++j) {
    if (j == 2) continue;
    Eigen::Index best = -1;
    double best_gap = 0.25;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index a = std::max<Eigen::Index>(0, i - 1), b = std::min(n - 1, i + 1);
      if (edf[a] < kMinEdf || edf[i] < kMinEdf || edf[b] < kMinEdf) continue;
      const double gap = std::abs(slope[i] - kSlope[static_cast<size_t>(j)]);
      if (gap <= best_gap) {
        best_gap = gap;
        best = i;
      }
    }
    if (best < 0) continue;
    const double raw = adev[best] / std::sqrt(Column(j, tau[best]));
    TermAt(*out, j)->slope_reading = ToReportUnit(j, raw);
    TermAt(*out, j)->slope_tau_s = tau[best];
  }
  // Bias instability: the flat bottom, B = min sigma / sqrt(2 ln2 / pi) = min / 0.664.
  Eigen::Index imin = 0;
  adev.minCoeff(&imin);
  out->b_dph.slope_reading = adev[imin] / std::sqrt(kBiasFactor);
  out->b_dph.slope_tau_s = tau[imin];
}

}  // namespace

void NoiseFitOptions::Validate() const {
  RequireNonNegative("tau_min_s", tau_min_s);
  if (!(tau_max_s > tau_min_s))
    ThrowOption("tau_max_s", FormatValue(tau_max_s),
                "> the smallest fitted tau (" + FormatValue(tau_min_s) + ")");
  if (!(min_share >= 0.0 && min_share < 1.0))
    ThrowOption("min_share", FormatValue(min_share), "in [0, 1)");
  if (!(significance > 0.0 && significance <= 0.5))
    ThrowOption("significance", FormatValue(significance), "in (0, 0.5]");
  if (!(sample_period_s >= 0.0 && std::isfinite(sample_period_s)))
    ThrowOption("sample_period_s", FormatValue(sample_period_s), "finite and >= 0");
}

double NoiseTerms::ModelDevDph(double tau_s) const {
  double var = 0.0;
  for (int j = 0; j < kTerms; ++j) {
    const double unit = ToReportUnit(j, 1.0);
    const double raw = TermAt(*this, j)->value / unit;
    var += raw * raw * Column(j, tau_s);
  }
  return std::sqrt(var);
}

std::string NoiseTerms::Summary() const {
  std::ostringstream s;
  auto put = [&](const char* name, const NoiseTerm& t, const char* unit) {
    s << name << " ";
    if (t.identified)
      s << FormatValue(t.value) << " +- " << FormatValue(t.sigma) << " " << unit;
    else
      s << "-";
  };
  put("Q", q_urad, "urad");
  s << ", ";
  put("N", n_dpsh, "deg/sqrt(h)");
  s << ", ";
  put("B", b_dph, "deg/h");
  s << ", ";
  put("K", k_dphpsh, "deg/h/sqrt(h)");
  s << ", ";
  put("R", r_dphph, "deg/h/h");
  s << " (" << points_used << " points, chi2/dof " << FormatValue(chi2_per_dof) << ")";
  return s.str();
}

namespace {

// Keeps points at least a factor sqrt(2) apart in tau (the first of each cluster): dense grids
// ("every averaging factor") add almost nothing but near-singular correlations.
std::vector<Eigen::Index> ThinToHalfOctaves(const std::vector<Eigen::Index>& use,
                                            const Eigen::VectorXd& tau_s) {
  std::vector<Eigen::Index> kept;
  for (const Eigen::Index i : use) {
    if (kept.empty() || tau_s[i] >= tau_s[kept.back()] * std::numbers::sqrt2 * (1.0 - 1e-9))
      kept.push_back(i);
  }
  return kept;
}

// Indices of the points fitted: positive finite deviations inside the options' tau range, thinned.
std::vector<Eigen::Index> FittedPoints(const Eigen::VectorXd& tau_s,
                                       const Eigen::VectorXd& adev_dph, const Eigen::VectorXd& edf,
                                       const NoiseFitOptions& options) {
  if (tau_s.size() != adev_dph.size() || tau_s.size() != edf.size())
    throw UsageError("IdentifyNoise: tau_s, adev_dph and edf must have the same length");
  std::vector<Eigen::Index> candidates;
  for (Eigen::Index i = 0; i < tau_s.size(); ++i) {
    if (!(tau_s[i] > 0.0) || !std::isfinite(adev_dph[i]) || !(adev_dph[i] > 0.0)) continue;
    if (tau_s[i] < options.tau_min_s || tau_s[i] > options.tau_max_s) continue;
    if (!candidates.empty() && !(tau_s[i] > tau_s[candidates.back()]))
      throw UsageError("IdentifyNoise: tau_s must increase");
    candidates.push_back(i);
  }
  std::vector<Eigen::Index> use = ThinToHalfOctaves(candidates, tau_s);
  if (use.size() < 2)
    throw DataError("noise fit needs at least 2 Allan points with positive deviation in [" +
                    FormatValue(options.tau_min_s) + ", " + FormatValue(options.tau_max_s) +
                    "] s (" + std::to_string(use.size()) + " found)");
  return use;
}

// The fitted points, n of them, with their model columns.
struct Points {
  Eigen::VectorXd tau, dev, var, edf;
  Eigen::VectorXd m;        // averaging factor tau / tau0
  Eigen::VectorXd terms;    // terms of each estimate (at least 1), or empty when not known
  Eigen::MatrixXd columns;  // n x 5
};

Points GatherPoints(const std::vector<Eigen::Index>& use, const Eigen::VectorXd& tau_s,
                    const Eigen::VectorXd& adev_dph, const Eigen::VectorXd& edf,
                    const Eigen::VectorXd& n_terms, double tau0_s) {
  const Eigen::Index n = static_cast<Eigen::Index>(use.size());
  Points p{.tau = Eigen::VectorXd(n),
           .dev = Eigen::VectorXd(n),
           .var = Eigen::VectorXd(n),
           .edf = Eigen::VectorXd(n),
           .m = Eigen::VectorXd(n),
           .terms = Eigen::VectorXd(n_terms.size() ? n : 0),
           .columns = Eigen::MatrixXd(n, kTerms)};
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Index i = use[static_cast<size_t>(r)];
    p.tau[r] = tau_s[i];
    p.dev[r] = adev_dph[i];
    p.var[r] = p.dev[r] * p.dev[r];
    p.edf[r] = std::isfinite(edf[i]) && edf[i] > 0.0 ? edf[i] : 1.0;
    p.m[r] = p.tau[r] / tau0_s;
    if (p.terms.size()) p.terms[r] = std::max(1.0, n_terms[i]);
    for (int j = 0; j < kTerms; ++j) p.columns(r, j) = Column(j, p.tau[r]);
  }
  return p;
}

// Every subset of the terms fitted in log variance. Weighted non-negative least squares on the
// variance (each point by the standard deviation of its AVAR estimate, var sqrt(2 / EDF)) gives
// their start values.
SubsetFits FitSubsets(const Points& p) {
  const Eigen::VectorXd sd = (p.var.array() * (2.0 / p.edf.array()).sqrt()).matrix();
  const Eigen::MatrixXd a = sd.asDiagonal().inverse() * p.columns;
  const Eigen::VectorXd b = p.var.cwiseQuotient(sd);
  if (!internal::SolveNnls(a, b, kAllTerms).ok)
    throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");
  return internal::FitAllSubsets(internal::MakeLogCurve(p.columns, p.var, p.edf), a, b, p.var);
}

// The selected model and the covariance of its coefficients (from ln c's: d c_j = c_j d u_j).
NnlsFit SelectedFit(const SubsetFits& fits, unsigned selected, const Evidence& evidence) {
  NnlsFit fit;
  fit.ok = true;
  fit.active = TermsOf(selected);
  fit.coef = fits[selected].coef;
  fit.chi2 = fits[selected].chi2;
  fit.cov = evidence.Covariance(selected);
  for (Eigen::Index c = 0; c < fit.cov.rows(); ++c) {
    const double cj = fit.coef[static_cast<size_t>(fit.active[static_cast<size_t>(c)])];
    fit.cov.row(c) *= cj;
    fit.cov.col(c) *= cj;
  }
  return fit;
}

// The identified terms' values, uncertainties and the taus where each carries min_share.
void ReportTerms(const NnlsFit& fit, const Eigen::VectorXd& tau, double min_share,
                 NoiseTerms* out) {
  const Eigen::Index n = tau.size();
  const double dof = static_cast<double>(n) - static_cast<double>(fit.active.size());
  out->chi2_per_dof = dof > 0 ? fit.chi2 / dof : 0.0;
  for (size_t c = 0; c < fit.active.size(); ++c) {
    const int j = fit.active[c];
    const double coef = fit.coef[static_cast<size_t>(j)];
    const double coef_sd =
        std::sqrt(fit.cov(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c)));
    const double raw = std::sqrt(coef);
    NoiseTerm* t = TermAt(*out, j);
    t->identified = true;
    t->value = ToReportUnit(j, raw);
    t->sigma = ToReportUnit(j, coef_sd / (2.0 * raw));
    for (Eigen::Index r = 0; r < n; ++r) {
      double model = 0.0;
      for (int k : fit.active) model += fit.coef[static_cast<size_t>(k)] * Column(k, tau[r]);
      if (coef * Column(j, tau[r]) >= min_share * model) {
        if (!(t->tau_lo_s <= tau[r])) t->tau_lo_s = tau[r];
        t->tau_hi_s = tau[r];
      }
    }
  }
}

NoiseTerms IdentifyNoiseImpl(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                             const Eigen::VectorXd& edf, const Eigen::VectorXd& n_terms,
                             double tau0_s, const NoiseFitOptions& options) {
  options.Validate();
  const std::vector<Eigen::Index> use = FittedPoints(tau_s, adev_dph, edf, options);
  if (!(tau0_s > 0.0)) tau0_s = tau_s[use.front()];
  const Points p = GatherPoints(use, tau_s, adev_dph, edf, n_terms, tau0_s);
  const Eigen::Index n = p.tau.size();
  NoiseTerms out;
  out.points_used = static_cast<int>(n);
  out.tau_min_s = p.tau.minCoeff();
  out.tau_max_s = p.tau.maxCoeff();
  Eigen::Index imin = 0;
  out.min_dev_dph = p.dev.minCoeff(&imin);
  out.min_dev_tau_s = p.tau[imin];

  const SubsetFits fits = FitSubsets(p);
  const unsigned largest = internal::LargestModel(fits);
  if (largest == 0) throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");
  // The correlation of the points, for the spectrum of the largest model (all terms free, so not
  // shaped by the selection), serves every test and the reported covariance. (The spectrum of the
  // selected model instead changes no coverage figure of docs/allan.md in the third digit, and
  // costs a second evaluation, about half the fit's time.)
  const Evidence evidence(fits, n, AvarCorrelation(p.m, fits[largest].coef, tau0_s, p.terms));
  const double critical = ChiSquareQuantile(1.0 - options.significance, 1.0);
  const unsigned selected =
      internal::SelectModel(fits, p.columns, options.min_share, critical, evidence);
  out.critical_chi2 = critical;
  for (int j = 0; j < kTerms; ++j) {
    const unsigned bit = 1u << j;
    TermAt(out, j)->evidence_chi2 =
        (selected & bit) ? evidence.Rise(selected, j) : evidence.Rise(selected | bit, j);
  }
  ReportTerms(SelectedFit(fits, selected, evidence), p.tau, options.min_share, &out);
  std::ostringstream note;
  note.precision(4);
  if (n <= kTerms) {
    note << n << " points fitted: at most " << n - 1 << " term" << (n == 2 ? "" : "s")
         << " can be told apart (chi2/dof " << out.chi2_per_dof
         << " with those kept), and a term the model lacks moves the others; a longer record or "
            "more taus in the fitted range identify more";
  } else if (out.chi2_per_dof > kMisfitNote) {
    note << "the five-term model misses this curve's shape (chi2/dof " << out.chi2_per_dof
         << " over " << out.tau_min_s << ".." << out.tau_max_s
         << " s): a sensor's filtering at the short taus or a drift at the long ones; fit a "
            "narrower tau range";
  }
  out.note = note.str();
  SlopeReadings(p.tau, p.dev, p.edf, &out);
  return out;
}

}  // namespace

NoiseTerms IdentifyNoise(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                         const Eigen::VectorXd& edf, const NoiseFitOptions& options) {
  // A curve from elsewhere: its taus and EDFs are checked, and its deviations are finite (points
  // without a positive deviation are passed over, as on an Allan result's longest taus).
  for (Eigen::Index i = 0; i < adev_dph.size(); ++i) {
    if (!std::isfinite(adev_dph[i])) {
      throw DataError("adev_dph point " + std::to_string(i + 1) + " is " +
                      FormatValue(adev_dph[i]) +
                      ": every deviation must be finite (0 where it was not measured)");
    }
  }
  for (Eigen::Index i = 0; i < std::min(tau_s.size(), edf.size()); ++i) {
    if (!(tau_s[i] > 0.0) || !std::isfinite(tau_s[i])) {
      throw DataError("tau_s point " + std::to_string(i + 1) + " is " + FormatValue(tau_s[i]) +
                      ": every tau must be a finite number > 0");
    }
    if (!(edf[i] > 0.0) || !std::isfinite(edf[i])) {
      throw DataError("edf point " + std::to_string(i + 1) + " is " + FormatValue(edf[i]) +
                      ": every EDF must be a finite number > 0");
    }
  }
  return IdentifyNoiseImpl(tau_s, adev_dph, edf, Eigen::VectorXd(), options.sample_period_s,
                           options);
}

NoiseTerms IdentifyNoise(const AllanResult& result, const NoiseFitOptions& options) {
  const Deviation d = result.options.deviation;
  if (d != Deviation::kAdev && d != Deviation::kOadev && d != Deviation::kTotdev)
    ThrowOption("deviation", ToString(d), "adev, oadev or totdev for the IEEE 952 noise fit");
  const Eigen::Index n = static_cast<Eigen::Index>(result.points.size());
  Eigen::VectorXd tau(n), dev(n), edf(n), n_terms(n);
  const double to_dph = ToDegPerHour(result.options.units);
  for (Eigen::Index i = 0; i < n; ++i) {
    const AllanPoint& p = result.points[static_cast<size_t>(i)];
    tau[i] = p.tau_s;
    dev[i] = p.dev * to_dph;
    edf[i] = std::isfinite(p.edf) && p.edf > 0.0 ? p.edf : static_cast<double>(p.n_terms);
    n_terms[i] = static_cast<double>(p.n_terms);
  }
  return IdentifyNoiseImpl(tau, dev, edf, n_terms, result.options.tau0_s(), options);
}

}  // namespace gyrodrift::allan
