// IEEE Std 952 noise terms from an Allan-variance curve (allan.h).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <sstream>

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

NoiseTerms IdentifyNoise(const Eigen::VectorXd& tau_s, const Eigen::VectorXd& adev_dph,
                         const Eigen::VectorXd& edf, const NoiseFitOptions& options) {
  options.Validate();
  if (tau_s.size() != adev_dph.size() || tau_s.size() != edf.size())
    throw UsageError("IdentifyNoise: tau_s, adev_dph and edf must have the same length");
  std::vector<Eigen::Index> use;
  for (Eigen::Index i = 0; i < tau_s.size(); ++i) {
    if (!(tau_s[i] > 0.0) || !std::isfinite(adev_dph[i]) || !(adev_dph[i] > 0.0)) continue;
    if (tau_s[i] < options.tau_min_s || tau_s[i] > options.tau_max_s) continue;
    use.push_back(i);
  }
  if (use.size() < 2)
    throw DataError("noise fit needs at least 2 Allan points with positive deviation in [" +
                    FormatValue(options.tau_min_s) + ", " + FormatValue(options.tau_max_s) +
                    "] s (" + std::to_string(use.size()) + " found)");
  const Eigen::Index n = static_cast<Eigen::Index>(use.size());
  Eigen::VectorXd tau(n), dev(n), point_edf(n);
  Eigen::MatrixXd a(n, kTerms);
  Eigen::VectorXd b(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Index i = use[static_cast<size_t>(r)];
    tau[r] = tau_s[i];
    dev[r] = adev_dph[i];
    const double var = dev[r] * dev[r];
    // Standard deviation of an AVAR estimate with `edf` degrees of freedom: var * sqrt(2 / edf).
    const double e = std::isfinite(edf[i]) && edf[i] > 0.0 ? edf[i] : 1.0;
    point_edf[r] = e;
    const double sd = var * std::sqrt(2.0 / e);
    for (int j = 0; j < kTerms; ++j) a(r, j) = Column(j, tau[r]) / sd;
    b[r] = var / sd;
  }
  NoiseTerms out;
  out.points_used = static_cast<int>(n);
  out.tau_min_s = tau.minCoeff();
  out.tau_max_s = tau.maxCoeff();
  Eigen::Index imin = 0;
  out.min_dev_dph = dev.minCoeff(&imin);
  out.min_dev_tau_s = tau[imin];

  // Fit, then drop terms that carry less than min_share of the model anywhere, and refit.
  unsigned allowed = (1u << kTerms) - 1;
  Fit fit;
  for (int round = 0; round < kTerms; ++round) {
    fit = SolveNnls(a, b, allowed);
    if (!fit.ok) break;
    unsigned keep = 0;
    for (int j : fit.active) {
      for (Eigen::Index r = 0; r < n; ++r) {
        double model = 0.0;
        for (int k : fit.active) model += fit.coef[static_cast<size_t>(k)] * Column(k, tau[r]);
        if (fit.coef[static_cast<size_t>(j)] * Column(j, tau[r]) >= options.min_share * model) {
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
  if (!fit.ok) throw DataError("noise fit: no non-negative combination of Q, N, B, K, R fits");
  const double dof = static_cast<double>(n) - static_cast<double>(fit.active.size());
  out.chi2_per_dof = dof > 0 ? fit.chi2 / dof : 0.0;
  // Neighbouring overlapping-Allan points are correlated, so the formal covariance is optimistic;
  // inflating it by the reduced chi-square (when > 1) at least reflects the misfit.
  const double inflate = std::max(1.0, out.chi2_per_dof);
  for (size_t c = 0; c < fit.active.size(); ++c) {
    const int j = fit.active[c];
    const double coef = fit.coef[static_cast<size_t>(j)];
    const double coef_sd =
        std::sqrt(fit.cov(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c)) * inflate);
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

NoiseTerms IdentifyNoise(const AllanResult& result, const NoiseFitOptions& options) {
  const Deviation d = result.options.deviation;
  if (d != Deviation::kAdev && d != Deviation::kOadev && d != Deviation::kTotdev)
    ThrowOption("deviation", ToString(d), "adev, oadev or totdev for the IEEE 952 noise fit");
  const Eigen::Index n = static_cast<Eigen::Index>(result.points.size());
  Eigen::VectorXd tau(n), dev(n), edf(n);
  const double to_dph = ToDegPerHour(result.options.units);
  for (Eigen::Index i = 0; i < n; ++i) {
    const AllanPoint& p = result.points[static_cast<size_t>(i)];
    tau[i] = p.tau_s;
    dev[i] = p.dev * to_dph;
    edf[i] = std::isfinite(p.edf) && p.edf > 0.0 ? p.edf : static_cast<double>(p.n_terms);
  }
  return IdentifyNoise(tau, dev, edf, options);
}

}  // namespace gyrodrift::allan
