// IEEE Std 952 noise terms from an Allan-variance curve (allan.h).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>

#include "allan/avar_correlation.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::allan {
namespace {

constexpr int kTerms = 5;                                               // Q, N, B, K, R
const double kBiasFactor = 2.0 * std::numbers::ln2 / std::numbers::pi;  // (0.664)^2

// Model column of term j at tau (s); coefficients are the squared raw terms in deg/h and s.
double Column(int j, double tau) {
  switch (j) {
    case 0:
      return 3.0 / (tau * tau);
    case 1:
      return 1.0 / tau;
    case 2:
      return kBiasFactor;
    case 3:
      return tau / 3.0;
    default:
      return 0.5 * tau * tau;
  }
}

// Raw term (sqrt of the coefficient, deg/h-and-seconds units) -> reporting unit.
double ToReportUnit(int j, double raw) {
  switch (j) {
    case 0:  // deg/h * s -> deg -> urad
      return raw / 3600.0 * std::numbers::pi / 180.0 * 1e6;
    case 1:  // deg/h * sqrt(s) -> deg/sqrt(h)
      return raw / 60.0;
    case 2:
      return raw;
    case 3:  // deg/h / sqrt(s) -> deg/h/sqrt(h)
      return raw * 60.0;
    default:  // deg/h / s -> deg/h/h
      return raw * 3600.0;
  }
}

struct Fit {
  std::array<double, kTerms> coef{};
  Eigen::MatrixXd cov;  // of the active coefficients, in `active` order
  std::vector<int> active;
  double chi2 = 0.0;
  bool ok = false;
};

// Exact non-negative least squares over a handful of columns: the NNLS optimum is the
// unconstrained optimum on its own support, so trying every support (at most 2^5) and keeping the
// best feasible one finds it without an iterative active-set method.
Fit SolveNnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, unsigned allowed) {
  Fit best;
  best.chi2 = std::numeric_limits<double>::infinity();
  for (unsigned mask = 1; mask < (1u << kTerms); ++mask) {
    if ((mask & ~allowed) != 0) continue;
    std::vector<int> cols;
    for (int j = 0; j < kTerms; ++j)
      if (mask & (1u << j)) cols.push_back(j);
    if (static_cast<Eigen::Index>(cols.size()) > a.rows()) continue;
    Eigen::MatrixXd sub(a.rows(), static_cast<Eigen::Index>(cols.size()));
    Eigen::VectorXd scale(sub.cols());
    for (Eigen::Index c = 0; c < sub.cols(); ++c) {
      sub.col(c) = a.col(cols[static_cast<size_t>(c)]);
      scale[c] = sub.col(c).norm();
      if (scale[c] == 0.0) scale[c] = 1.0;
      sub.col(c) /= scale[c];  // equilibrate: tau^-2 and tau^2 columns differ by ~1e16
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(sub);
    if (qr.rank() < sub.cols()) continue;
    Eigen::VectorXd x = qr.solve(b);
    if ((x.array() <= 0.0).any()) continue;
    const double chi2 = (sub * x - b).squaredNorm();
    if (chi2 < best.chi2) {
      best = Fit{};
      best.chi2 = chi2;
      best.ok = true;
      best.active = cols;
      const Eigen::MatrixXd r = qr.matrixR()
                                    .topLeftCorner(sub.cols(), sub.cols())
                                    .template triangularView<Eigen::Upper>();
      // (A^T A)^-1 = P R^-1 R^-T P^T, then undo the equilibration.
      const Eigen::MatrixXd rinv =
          r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(sub.cols(), sub.cols()));
      const Eigen::MatrixXd perm = qr.colsPermutation();
      Eigen::MatrixXd cov = perm * rinv * rinv.transpose() * perm.transpose();
      for (Eigen::Index i = 0; i < cov.rows(); ++i)
        for (Eigen::Index j = 0; j < cov.cols(); ++j) cov(i, j) /= scale[i] * scale[j];
      best.cov = cov;
      for (size_t c = 0; c < cols.size(); ++c)
        best.coef[static_cast<size_t>(cols[c])] =
            x[static_cast<Eigen::Index>(c)] / scale[static_cast<Eigen::Index>(c)];
    }
  }
  return best;
}

NoiseTerm* TermAt(NoiseTerms& t, int j) {
  switch (j) {
    case 0:
      return &t.q_urad;
    case 1:
      return &t.n_dpsh;
    case 2:
      return &t.b_dph;
    case 3:
      return &t.k_dphpsh;
    default:
      return &t.r_dphph;
  }
}
const NoiseTerm* TermAt(const NoiseTerms& t, int j) {
  return TermAt(const_cast<NoiseTerms&>(t), j);
}

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
    ThrowOption("tau_max_s", FormatValue(tau_max_s), "> tau_min_s = " + FormatValue(tau_min_s));
  if (!(min_share >= 0.0 && min_share < 1.0))
    ThrowOption("min_share", FormatValue(min_share), "in [0, 1)");
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

// The non-negative fit on whitened columns, then: drop terms that carry less than min_share of
// the model anywhere, and refit.
Fit FitDroppingMinorTerms(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& tau, double min_share) {
  unsigned allowed = (1u << kTerms) - 1;
  Fit fit;
  for (int round = 0; round < kTerms; ++round) {
    fit = SolveNnls(a, b, allowed);
    if (!fit.ok) break;
    unsigned keep = 0;
    for (int j : fit.active) {
      for (Eigen::Index r = 0; r < tau.size(); ++r) {
        double model = 0.0;
        for (int k : fit.active) model += fit.coef[static_cast<size_t>(k)] * Column(k, tau[r]);
        if (fit.coef[static_cast<size_t>(j)] * Column(j, tau[r]) >= min_share * model) {
          keep |= 1u << j;
          break;
        }
      }
    }
    unsigned active = 0;
    for (int j : fit.active) active |= 1u << j;
    if (keep == active || keep == 0) break;
    allowed = keep;
  }
  return fit;
}

// Digamma and trigamma for x > 0: recurrence up to x >= 8, then the asymptotic series.
double Digamma(double x) {
  double shift = 0.0;
  for (; x < 8.0; x += 1.0) shift -= 1.0 / x;
  const double x2 = 1.0 / (x * x);
  return shift + std::log(x) - 0.5 / x -
         x2 * (1.0 / 12.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 252.0 - x2 / 240.0)));
}
double Trigamma(double x) {
  double shift = 0.0;
  for (; x < 8.0; x += 1.0) shift += 1.0 / (x * x);
  const double x2 = 1.0 / (x * x);
  return shift + 1.0 / x + 0.5 * x2 +
         x2 / x * (1.0 / 6.0 - x2 * (1.0 / 30.0 - x2 * (1.0 / 42.0 - x2 / 30.0)));
}

// Refines a fit in log variance, where every point's error has a known law that does not depend
// on its value: an AVAR estimate with EDF nu is AVAR * chi2_nu / nu, so ln(estimate) has mean
// ln AVAR + psi(nu/2) - ln(nu/2) and variance psi'(nu/2). Fitting the variances themselves with
// weights from the measured values overweights points that came out low, which biases the
// long-tau terms (K, R) low by about one standard error; weights from the model instead let the
// model float above the tail of real curves. The log fit has neither problem, and it minimises
// the misfit one sees on a log-log plot. Levenberg-Marquardt in u_j = ln c_j (so c_j > 0) from
// the weighted fit. Terms that end below min_share everywhere, and the least significant term
// if its value is below its own standard uncertainty (the data cannot tell it from zero), are
// dropped and the rest refitted. The covariance is the sandwich (J'J)^-1 J' rho J (J'J)^-1 with
// rho the correlation of the points (avar_correlation.h), widened by the reduced chi-square when
// that exceeds 1 (the model misses something: a drift, a noise type outside the five).
Fit RefineInLogVariance(
    const Eigen::MatrixXd& columns, const Eigen::VectorXd& var, const Eigen::VectorXd& edf,
    const Fit& start, double min_share,
    const std::function<Eigen::MatrixXd(const std::array<double, kTerms>&)>& correlation) {
  const Eigen::Index n = var.size();
  Eigen::VectorXd target(n), sd(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    target[r] = std::log(var[r]) - (Digamma(edf[r] / 2.0) - std::log(edf[r] / 2.0));
    sd[r] = std::sqrt(Trigamma(edf[r] / 2.0));
  }
  Fit fit = start;
  for (int round = 0; round < kTerms; ++round) {
    const auto k = static_cast<Eigen::Index>(fit.active.size());
    Eigen::VectorXd u(k);
    for (Eigen::Index c = 0; c < k; ++c) u[c] = std::log(fit.coef[static_cast<size_t>(fit.active[c])]);
    auto evaluate = [&](const Eigen::VectorXd& at, Eigen::VectorXd* residual,
                        Eigen::MatrixXd* jacobian) {
      for (Eigen::Index r = 0; r < n; ++r) {
        double model = 0.0;
        for (Eigen::Index c = 0; c < k; ++c) model += std::exp(at[c]) * columns(r, fit.active[c]);
        (*residual)[r] = (target[r] - std::log(model)) / sd[r];
        if (jacobian)
          for (Eigen::Index c = 0; c < k; ++c)
            (*jacobian)(r, c) = std::exp(at[c]) * columns(r, fit.active[c]) / model / sd[r];
      }
      return residual->squaredNorm();
    };
    Eigen::VectorXd residual(n), trial_residual(n);
    Eigen::MatrixXd jacobian(n, k);
    double cost = evaluate(u, &residual, &jacobian);
    double lambda = 1e-3;
    for (int iteration = 0; iteration < 200; ++iteration) {
      const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
      Eigen::MatrixXd damped = normal;
      damped.diagonal() *= 1.0 + lambda;
      const Eigen::VectorXd step = damped.ldlt().solve(jacobian.transpose() * residual);
      const Eigen::VectorXd trial = u + step;
      const double trial_cost = evaluate(trial, &trial_residual, nullptr);
      if (std::isfinite(trial_cost) && trial_cost <= cost) {
        const bool converged = cost - trial_cost <= 1e-14 * (1.0 + cost) &&
                               step.cwiseAbs().maxCoeff() < 1e-9;
        u = trial;
        cost = evaluate(u, &residual, &jacobian);
        lambda = std::max(lambda / 10.0, 1e-12);
        if (converged) break;
      } else {
        lambda *= 10.0;
        if (lambda > 1e12) break;
      }
    }
    Fit refined;
    refined.ok = true;
    refined.active = fit.active;
    for (Eigen::Index c = 0; c < k; ++c)
      refined.coef[static_cast<size_t>(fit.active[c])] = std::exp(u[c]);
    refined.chi2 = cost;
    const Eigen::MatrixXd bread =
        (jacobian.transpose() * jacobian).ldlt().solve(Eigen::MatrixXd::Identity(k, k));
    const double dof = static_cast<double>(n - k);
    const double inflate = dof > 0 ? std::max(1.0, cost / dof) : 1.0;
    refined.cov = inflate * bread *
                  (jacobian.transpose() * correlation(refined.coef) * jacobian) * bread;  // of u
    std::vector<int> keep;
    const Eigen::VectorXd model =
        columns * Eigen::Map<const Eigen::VectorXd>(refined.coef.data(), kTerms);
    for (const int j : refined.active) {
      for (Eigen::Index r = 0; r < n; ++r) {
        if (refined.coef[static_cast<size_t>(j)] * columns(r, j) >= min_share * model[r]) {
          keep.push_back(j);
          break;
        }
      }
    }
    if (keep.size() == refined.active.size() && k > 1) {
      Eigen::Index worst = 0;
      refined.cov.diagonal().maxCoeff(&worst);
      // sd(ln c) > 2 <=> sd(sqrt c) / sqrt c > 1
      if (refined.cov(worst, worst) > 4.0) keep.erase(keep.begin() + worst);
    }
    fit = refined;
    if (keep.size() == refined.active.size() || keep.empty()) break;
    fit.active = keep;
    for (int j = 0; j < kTerms; ++j)
      if (std::find(keep.begin(), keep.end(), j) == keep.end()) fit.coef[static_cast<size_t>(j)] = 0.0;
  }
  // From ln c to c: d c_j = c_j d u_j.
  for (size_t c = 0; c < fit.active.size(); ++c) {
    const double cj = fit.coef[static_cast<size_t>(fit.active[c])];
    fit.cov.row(static_cast<Eigen::Index>(c)) *= cj;
    fit.cov.col(static_cast<Eigen::Index>(c)) *= cj;
  }
  return fit;
}

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

NoiseTerms IdentifyNoiseImpl(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                             const Eigen::VectorXd& edf, const Eigen::VectorXd& n_terms,
                             double tau0_s, const NoiseFitOptions& options) {
  options.Validate();
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
  const std::vector<Eigen::Index> use = ThinToHalfOctaves(candidates, tau_s);
  if (use.size() < 2)
    throw DataError("noise fit needs at least 2 Allan points with positive deviation in [" +
                    FormatValue(options.tau_min_s) + ", " + FormatValue(options.tau_max_s) +
                    "] s (" + std::to_string(use.size()) + " found)");
  const Eigen::Index n = static_cast<Eigen::Index>(use.size());
  if (!(tau0_s > 0.0)) tau0_s = tau_s[use.front()];
  Eigen::VectorXd tau(n), dev(n), var(n), point_edf(n), m(n), terms(n_terms.size() ? n : 0);
  Eigen::MatrixXd columns(n, kTerms);
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Index i = use[static_cast<size_t>(r)];
    tau[r] = tau_s[i];
    dev[r] = adev_dph[i];
    var[r] = dev[r] * dev[r];
    point_edf[r] = std::isfinite(edf[i]) && edf[i] > 0.0 ? edf[i] : 1.0;
    m[r] = tau[r] / tau0_s;
    if (terms.size()) terms[r] = std::max(1.0, n_terms[i]);
    for (int j = 0; j < kTerms; ++j) columns(r, j) = Column(j, tau[r]);
  }
  NoiseTerms out;
  out.points_used = static_cast<int>(n);
  out.tau_min_s = tau.minCoeff();
  out.tau_max_s = tau.maxCoeff();
  Eigen::Index imin = 0;
  out.min_dev_dph = dev.minCoeff(&imin);
  out.min_dev_tau_s = tau[imin];

  // Each point weighted by the standard deviation of its AVAR estimate, var * sqrt(2 / EDF).
  // (Weights from the fitted model instead of the measured variance, iterated, remove a small
  // downward bias but let the fit float above the tail of real curves: tested, not kept.)
  const Eigen::VectorXd sd = (var.array() * (2.0 / point_edf.array()).sqrt()).matrix();
  Fit fit = FitDroppingMinorTerms(sd.asDiagonal().inverse() * columns,
                                  var.cwiseQuotient(sd), tau, options.min_share);
  if (fit.ok) {
    fit = RefineInLogVariance(columns, var, point_edf, fit, options.min_share,
                              [&](const std::array<double, kTerms>& coef) {
                                return AvarCorrelation(m, coef, tau0_s, terms);
                              });
  }
  if (!fit.ok) throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");
  const double dof = static_cast<double>(n) - static_cast<double>(fit.active.size());
  out.chi2_per_dof = dof > 0 ? fit.chi2 / dof : 0.0;
  for (size_t c = 0; c < fit.active.size(); ++c) {
    const int j = fit.active[c];
    const double coef = fit.coef[static_cast<size_t>(j)];
    const double coef_sd =
        std::sqrt(fit.cov(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c)));
    const double raw = std::sqrt(coef);
    NoiseTerm* t = TermAt(out, j);
    t->identified = true;
    t->value = ToReportUnit(j, raw);
    t->sigma = ToReportUnit(j, coef_sd / (2.0 * raw));
    for (Eigen::Index r = 0; r < n; ++r) {
      double model = 0.0;
      for (int k : fit.active) model += fit.coef[static_cast<size_t>(k)] * Column(k, tau[r]);
      if (coef * Column(j, tau[r]) >= options.min_share * model) {
        if (!(t->tau_lo_s <= tau[r])) t->tau_lo_s = tau[r];
        t->tau_hi_s = tau[r];
      }
    }
  }
  SlopeReadings(tau, dev, point_edf, &out);
  return out;
}

}  // namespace

NoiseTerms IdentifyNoise(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                         const Eigen::VectorXd& edf, const NoiseFitOptions& options) {
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
