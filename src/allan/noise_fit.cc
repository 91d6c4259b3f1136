// IEEE Std 952 noise terms from an Allan-variance curve (allan.h).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

#include "allan/avar_correlation.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/allan/edf.h"
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

constexpr unsigned kAllTerms = (1u << kTerms) - 1;

int Size(unsigned mask) { return std::popcount(mask); }

std::vector<int> TermsOf(unsigned mask) {
  std::vector<int> terms;
  for (int j = 0; j < kTerms; ++j)
    if (mask & (1u << j)) terms.push_back(j);
  return terms;
}

// A curve in log variance. An AVAR estimate with EDF nu is AVAR chi2_nu / nu, so its logarithm has
// mean ln AVAR + psi(nu/2) - ln(nu/2) and variance psi'(nu/2) whatever its value. Fitting the
// variances themselves with weights from the measured values overweights points that came out
// low, which biases the long-tau terms (K, R) low by about one standard error; weights from the
// model instead let the model float above the tail of real curves. The log fit has neither
// problem, and it minimises the misfit one sees on a log-log plot.
struct LogCurve {
  Eigen::MatrixXd columns;  // n x 5 model columns
  Eigen::VectorXd target;   // ln(var) - (psi(nu/2) - ln(nu/2))
  Eigen::VectorXd sd;       // sqrt(psi'(nu/2))
};

struct SubsetFit {
  std::array<double, kTerms> coef{};                      // 0 for terms outside the subset
  double chi2 = std::numeric_limits<double>::infinity();  // sum of squared standardised residuals
  Eigen::MatrixXd jacobian;  // d residual / d ln c_j at the optimum, active terms in index order
  bool ok = false;
};

// Levenberg-Marquardt on u_j = ln c_j (so every coefficient stays positive) for the terms in
// `mask`, from `start`. A term whose optimum is zero drifts towards it (and is then removed by the
// selection, where it changes nothing).
SubsetFit FitLog(const LogCurve& d, unsigned mask, const std::array<double, kTerms>& start) {
  const std::vector<int> active = TermsOf(mask);
  const Eigen::Index n = d.target.size();
  const auto k = static_cast<Eigen::Index>(active.size());
  Eigen::VectorXd u(k);
  for (Eigen::Index c = 0; c < k; ++c) u[c] = std::log(start[static_cast<size_t>(active[c])]);
  auto evaluate = [&](const Eigen::VectorXd& at, Eigen::VectorXd* residual,
                      Eigen::MatrixXd* jacobian) {
    const Eigen::VectorXd coef = at.array().exp();
    for (Eigen::Index r = 0; r < n; ++r) {
      double model = 0.0;
      for (Eigen::Index c = 0; c < k; ++c) model += coef[c] * d.columns(r, active[c]);
      (*residual)[r] = (d.target[r] - std::log(model)) / d.sd[r];
      if (jacobian)
        for (Eigen::Index c = 0; c < k; ++c)
          (*jacobian)(r, c) = coef[c] * d.columns(r, active[c]) / model / d.sd[r];
    }
    return residual->squaredNorm();
  };
  SubsetFit fit;
  Eigen::VectorXd residual(n), trial_residual(n);
  Eigen::MatrixXd jacobian(n, k);
  double cost = evaluate(u, &residual, &jacobian);
  if (!std::isfinite(cost)) return fit;
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 200; ++iteration) {
    Eigen::MatrixXd damped = jacobian.transpose() * jacobian;
    damped.diagonal() *= 1.0 + lambda;
    const Eigen::VectorXd step = damped.ldlt().solve(jacobian.transpose() * residual);
    const Eigen::VectorXd trial = u + step;
    const double trial_cost = evaluate(trial, &trial_residual, nullptr);
    if (std::isfinite(trial_cost) && trial_cost <= cost) {
      const bool converged =
          cost - trial_cost <= 1e-14 * (1.0 + cost) && step.cwiseAbs().maxCoeff() < 1e-9;
      u = trial;
      cost = evaluate(u, &residual, &jacobian);
      lambda = std::max(lambda / 10.0, 1e-12);
      if (converged) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) break;
    }
  }
  fit.ok = true;
  fit.chi2 = cost;
  fit.jacobian = jacobian;
  for (Eigen::Index c = 0; c < k; ++c) fit.coef[static_cast<size_t>(active[c])] = std::exp(u[c]);
  return fit;
}

using SubsetFits = std::array<SubsetFit, 1u << kTerms>;  // indexed by the mask of the terms

// Every subset of the five terms (at most n terms). Subsets are visited by size; each starts from
// the weighted non-negative fit in variance on its terms and from each one-term-smaller fit plus a
// little of the added term, and keeps the best, so a model never fits worse than the models
// nested in it.
SubsetFits FitAllSubsets(const LogCurve& d, const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                         const Eigen::VectorXd& var) {
  SubsetFits fits;
  const Eigen::Index n = d.target.size();
  for (int size = 1; size <= std::min<Eigen::Index>(kTerms, n); ++size) {
    for (unsigned mask = 1; mask <= kAllTerms; ++mask) {
      if (Size(mask) != size) continue;
      // A term missing from a start begins at 1 % of the most it could be without exceeding the
      // curve anywhere.
      auto complete = [&](std::array<double, kTerms> coef) {
        for (const int j : TermsOf(mask)) {
          if (coef[static_cast<size_t>(j)] > 0.0) continue;
          double most = std::numeric_limits<double>::infinity();
          for (Eigen::Index r = 0; r < n; ++r) most = std::min(most, var[r] / d.columns(r, j));
          coef[static_cast<size_t>(j)] = 0.01 * most;
        }
        return coef;
      };
      std::vector<std::array<double, kTerms>> starts;
      const Fit nnls = SolveNnls(a, b, mask);
      starts.push_back(complete(nnls.ok ? nnls.coef : std::array<double, kTerms>{}));
      for (const int j : TermsOf(mask)) {
        const SubsetFit& smaller = fits[mask & ~(1u << j)];
        if (smaller.ok) starts.push_back(complete(smaller.coef));
      }
      for (const auto& start : starts) {
        SubsetFit fit = FitLog(d, mask, start);
        if (fit.ok && fit.chi2 < fits[mask].chi2) fits[mask] = std::move(fit);
      }
    }
  }
  return fits;
}

// Does term j carry at least `share` of the fitted model variance at some tau?
bool Carries(const SubsetFit& fit, int j, const Eigen::MatrixXd& columns, double share) {
  for (Eigen::Index r = 0; r < columns.rows(); ++r) {
    double model = 0.0;
    for (int k = 0; k < kTerms; ++k) model += fit.coef[static_cast<size_t>(k)] * columns(r, k);
    if (fit.coef[static_cast<size_t>(j)] * columns(r, j) >= share * model) return true;
  }
  return false;
}

// The misfit above treats the points as independent, but neighbouring points share most of their
// data (for white rate noise the OADEV variances at tau and 2 tau are correlated at about 0.7), so
// its differences between nested models are not chi-square with 1 degree of freedom, and the
// model-based covariance of the fit is several times too small. Both are corrected with the
// correlation rho of the points for Gaussian noise with the fitted spectrum (avar_correlation.h):
// the covariance of ln c is the sandwich (J'J)^-1 J' rho J (J'J)^-1, and the rise of the misfit
// when term j is removed is divided by the design effect delta_j = sandwich_jj / (J'J)^-1_jj (the
// first-order Rao-Scott correction: under the smaller model the rise is delta_j chi2_1). When the
// reduced chi-square exceeds 1 (the model misses something: a drift, filtering, a noise type
// outside the five) the covariance is widened, and the rise divided, by it, so that a poor fit
// does not make every term look significant. (Generalised least squares, whitening the residuals
// with rho, would make the misfit chi-square directly, but it amplifies every departure of a real
// curve from the five-term shape: it reduced the KVH 1750 X curve to white rate noise alone, which
// leaves the published band at four taus.)
class Evidence {
 public:
  // `rho`: the correlation of the points (avar_correlation.h).
  Evidence(const SubsetFits& fits, Eigen::Index n, Eigen::MatrixXd rho)
      : fits_(fits), n_(n), rho_(std::move(rho)) {}

  // Residual variance factor of a model: max(1, chi2 / dof).
  double Scale(unsigned mask) const {
    const Eigen::Index dof = n_ - Size(mask);
    return dof > 0 ? std::max(1.0, fits_[mask].chi2 / static_cast<double>(dof)) : 1.0;
  }

  // Covariance of ln c of the model's active terms: the sandwich, widened by Scale; `naive` gets
  // (J'J)^-1. The columns of the Jacobian are equilibrated first: a term drifting to its bound of
  // zero has a vanishing column, and neither the sandwich nor the design effect depends on the
  // scale of a parameter. A column that is exactly zero (a coefficient that underflowed) is left
  // out.
  Eigen::MatrixXd Covariance(unsigned mask, Eigen::MatrixXd* naive = nullptr) const {
    const Eigen::MatrixXd& jacobian = fits_[mask].jacobian;
    const Eigen::Index k = jacobian.cols();
    std::vector<Eigen::Index> live;
    for (Eigen::Index c = 0; c < k; ++c)
      if (jacobian.col(c).norm() > 0.0) live.push_back(c);
    const auto l = static_cast<Eigen::Index>(live.size());
    Eigen::MatrixXd scaled(jacobian.rows(), l);
    Eigen::VectorXd norm(l);
    for (Eigen::Index c = 0; c < l; ++c) {
      norm[c] = jacobian.col(live[static_cast<size_t>(c)]).norm();
      scaled.col(c) = jacobian.col(live[static_cast<size_t>(c)]) / norm[c];
    }
    const Eigen::MatrixXd bread =
        (scaled.transpose() * scaled).ldlt().solve(Eigen::MatrixXd::Identity(l, l));
    const Eigen::MatrixXd sandwich =
        Scale(mask) * bread * (scaled.transpose() * rho_ * scaled) * bread;
    Eigen::MatrixXd robust = Eigen::MatrixXd::Zero(k, k);
    if (naive) *naive = Eigen::MatrixXd::Zero(k, k);
    for (Eigen::Index i = 0; i < l; ++i) {
      for (Eigen::Index j = 0; j < l; ++j) {
        const auto a = live[static_cast<size_t>(i)], b = live[static_cast<size_t>(j)];
        robust(a, b) = sandwich(i, j) / (norm[i] * norm[j]);
        if (naive) (*naive)(a, b) = bread(i, j) / (norm[i] * norm[j]);
      }
    }
    return robust;
  }

  // Corrected rise of the misfit from `larger` to `larger` without term j (chi-square units with
  // 1 degree of freedom under the smaller model); NaN if either model could not be fitted.
  double Rise(unsigned larger, int j) const {
    const unsigned smaller = larger & ~(1u << j);
    if (!fits_[smaller].ok || !fits_[larger].ok) return std::numeric_limits<double>::quiet_NaN();
    const double rise = std::max(0.0, fits_[smaller].chi2 - fits_[larger].chi2);
    const std::vector<int> active = TermsOf(larger);
    const auto c =
        static_cast<Eigen::Index>(std::find(active.begin(), active.end(), j) - active.begin());
    Eigen::MatrixXd naive;
    const Eigen::MatrixXd robust = Covariance(larger, &naive);
    double effect = robust(c, c) / naive(c, c);  // includes Scale(larger)
    if (!(effect > 0.0) || !std::isfinite(effect)) effect = Scale(larger);
    return rise / effect;
  }

 private:
  const SubsetFits& fits_;
  Eigen::Index n_;
  Eigen::MatrixXd rho_;
};

// The best-fitting model of the largest size the points allow (all five terms from five points).
unsigned LargestModel(const SubsetFits& fits) {
  unsigned largest = 0;
  for (unsigned m = 1; m <= kAllTerms; ++m) {
    if (!fits[m].ok) continue;
    if (largest == 0 || Size(m) > Size(largest) ||
        (Size(m) == Size(largest) && fits[m].chi2 < fits[largest].chi2))
      largest = m;
  }
  return largest;
}

// Model selection by nested tests in the order of the IEEE 952 hierarchy. The model is a
// polynomial in tau and 1/tau, c_Q 3/tau^2 + c_N/tau + c_B 2ln2/pi + c_K tau/3 + c_R tau^2/2; as
// in polynomial regression, the steepest terms are tested for removal first: R and Q (tau^+-2),
// then K and N (tau^+-1), the flat bias-instability floor B last. From the largest model the
// points allow, the first term in that order that never carries min_share of the model, or whose
// removal raises the corrected misfit by less than `critical`, is removed, and the tests start
// again on the smaller model.
// Why an order: neighbouring terms overlap. Over the last octaves of a record a rising K and a
// flat B explain the same excess over the white rate noise, and which fits a little better is
// decided by the scatter of the last, least certain points. Keeping the best-fitting model of each
// size, or removing the least significant term first (the rule before this one), reports a rate
// random walk in about a quarter of 8-hour records of a navigation FOG whose K cannot show in 8
// hours (docs/allan.md); tested steepest first, a rise is claimed only where the curve rises
// significantly above a floor.
unsigned SelectModel(const SubsetFits& fits, const Eigen::MatrixXd& columns, double min_share,
                     double critical, const Evidence& evidence) {
  constexpr std::array<int, kTerms> kRemovalOrder{4, 0, 3, 1, 2};  // R, Q, K, N, B
  unsigned mask = LargestModel(fits);
  auto removable = [&](int j) {
    return (mask & (1u << j)) && Size(mask) > 1 && fits[mask & ~(1u << j)].ok;
  };
  while (mask != 0) {
    int remove = -1;
    for (const int j : kRemovalOrder) {
      if (removable(j) &&
          (!Carries(fits[mask], j, columns, min_share) || !(evidence.Rise(mask, j) >= critical))) {
        remove = j;
        break;
      }
    }
    if (remove < 0) break;
    mask &= ~(1u << remove);
  }
  return mask;
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

  // Weighted non-negative least squares on the variance (each point by the standard deviation of
  // its AVAR estimate, var sqrt(2 / EDF)): the start values of the log fits.
  const Eigen::VectorXd sd = (var.array() * (2.0 / point_edf.array()).sqrt()).matrix();
  const Eigen::MatrixXd a = sd.asDiagonal().inverse() * columns;
  const Eigen::VectorXd b = var.cwiseQuotient(sd);
  if (!SolveNnls(a, b, kAllTerms).ok)
    throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");

  LogCurve curve;
  curve.columns = columns;
  curve.target.resize(n);
  curve.sd.resize(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const double half = point_edf[r] / 2.0;
    curve.target[r] = std::log(var[r]) - (Digamma(half) - std::log(half));
    curve.sd[r] = std::sqrt(Trigamma(half));
  }
  const SubsetFits fits = FitAllSubsets(curve, a, b, var);
  const unsigned largest = LargestModel(fits);
  if (largest == 0) throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");
  // The correlation of the points, for the spectrum of the largest model (all terms free, so not
  // shaped by the selection), serves every test and the reported covariance. (The spectrum of the
  // selected model instead changes no coverage figure of docs/allan.md in the third digit, and
  // costs a second evaluation, about half the fit's time.)
  const Evidence evidence(fits, n, AvarCorrelation(m, fits[largest].coef, tau0_s, terms));
  const double critical = ChiSquareQuantile(1.0 - options.significance, 1.0);
  const unsigned selected = SelectModel(fits, columns, options.min_share, critical, evidence);
  Fit fit;
  fit.ok = true;
  fit.active = TermsOf(selected);
  fit.coef = fits[selected].coef;
  fit.chi2 = fits[selected].chi2;
  fit.cov = evidence.Covariance(selected);  // of ln c, then of c: d c_j = c_j d u_j
  for (Eigen::Index c = 0; c < fit.cov.rows(); ++c) {
    const double cj = fit.coef[static_cast<size_t>(fit.active[static_cast<size_t>(c)])];
    fit.cov.row(c) *= cj;
    fit.cov.col(c) *= cj;
  }
  out.critical_chi2 = critical;
  for (int j = 0; j < kTerms; ++j) {
    const unsigned bit = 1u << j;
    TermAt(out, j)->evidence_chi2 =
        (selected & bit) ? evidence.Rise(selected, j) : evidence.Rise(selected | bit, j);
  }
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
