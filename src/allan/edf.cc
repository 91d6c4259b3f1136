// Equivalent degrees of freedom, chi-square quantiles and lag-1 autocorrelation noise
// identification for allan.h.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "allan/kernels.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/edf.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::allan {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kWilsonHilfertyDof = 1e4;
constexpr Eigen::Index kMinPoints = 30;  // fewest points noise identification works on
// Phase samples per chunk of the batched identification's sweeps (32 KiB: the chunk stays in L1
// while every factor takes its points from it).
constexpr Eigen::Index kScanChunk = 4096;

// ---- Greenhall & Riley 2003 ------------------------------------------------------------------
// Generalized autocovariance of the phase increments for power-law noise alpha (their eq. 7).
double Sw(double t, int alpha) {
  const double a = std::abs(t);
  switch (alpha) {
    case 2:
      return -a;
    case 1:
      return a == 0.0 ? 0.0 : t * t * std::log(a);
    case 0:
      return a * a * a;
    case -1:
      return a == 0.0 ? 0.0 : t * t * t * t * std::log(a);
    case -2:
      return a * a * a * a * a;
    case -3:
      return a == 0.0 ? 0.0 : std::pow(t, 6) * std::log(a);
    case -4:
      return std::pow(a, 7);
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

// Averaging by F (F = inf: the continuous limit, which raises the noise order by 2). Eq. 8.
double Sx(double t, double f, int alpha) {
  if (f == kInf) return Sw(t, alpha + 2);
  return f * f * (2.0 * Sw(t, alpha) - Sw(t - 1.0 / f, alpha) - Sw(t + 1.0 / f, alpha));
}

// d-th difference: binomial weights (-1)^k C(2d, d+k). Eq. 9.
double Sz(double t, double f, int alpha, int d) {
  static constexpr double kW[4][4] = {{1, 0, 0, 0}, {2, -1, 0, 0}, {6, -4, 1, 0}, {20, -15, 6, -1}};
  double s = kW[d][0] * Sx(t, f, alpha);
  for (int k = 1; k <= d; ++k) s += kW[d][k] * (Sx(t - k, f, alpha) + Sx(t + k, f, alpha));
  return s;
}

// Eq. 10.
double BasicSum(double j_terms, double m_terms, double s, double f, int alpha, int d) {
  const double z0 = Sz(0.0, f, alpha, d);
  double sum = z0 * z0;
  const double zj = Sz(j_terms / s, f, alpha, d);
  sum += (1.0 - j_terms / m_terms) * zj * zj;
  for (int j = 1; j < static_cast<int>(j_terms); ++j) {
    const double z = Sz(j / s, f, alpha, d);
    sum += 2.0 * (1.0 - j / m_terms) * z * z;
  }
  return sum;
}

// Table 1 (modified variances) and 2 (unmodified) of Greenhall & Riley: (a0, a1) for
// alpha = 2..-4 (rows) and d = 1..3 (columns); NaN where alpha + 2d <= 1.
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTable1[7][3][2] = {
    {{2.0 / 3, 1.0 / 3}, {7.0 / 9, 1.0 / 2}, {22.0 / 25, 2.0 / 3}},
    {{0.840, 0.345}, {0.997, 0.616}, {1.141, 0.843}},
    {{1.079, 0.368}, {1.033, 0.607}, {1.184, 0.848}},
    {{kNaN, kNaN}, {1.048, 0.534}, {1.180, 0.816}},
    {{kNaN, kNaN}, {1.302, 0.535}, {1.175, 0.777}},
    {{kNaN, kNaN}, {kNaN, kNaN}, {1.194, 0.703}},
    {{kNaN, kNaN}, {kNaN, kNaN}, {1.489, 0.702}},
};
constexpr double kTable2[7][3][2] = {
    {{3.0 / 2, 1.0 / 2}, {35.0 / 18, 1.0}, {231.0 / 100, 3.0 / 2}},
    {{78.6, 25.2}, {790.0, 410.0}, {9950.0, 6520.0}},
    {{2.0 / 3, 1.0 / 6}, {2.0 / 3, 1.0 / 3}, {7.0 / 9, 1.0 / 2}},
    {{kNaN, kNaN}, {0.852, 0.375}, {0.997, 0.617}},
    {{kNaN, kNaN}, {1.079, 0.368}, {1.033, 0.607}},
    {{kNaN, kNaN}, {kNaN, kNaN}, {1.053, 0.553}},
    {{kNaN, kNaN}, {kNaN, kNaN}, {1.302, 0.535}},
};
// Table 3: flicker PM, unmodified: (b0, b1) by d.
constexpr double kTable3[3][2] = {{6.0, 4.0}, {15.23, 12.0}, {47.8, 40.0}};

// Greenhall & Riley's algorithm. Filter factor F = 1 for modified variances, m for unmodified;
// stride factor S = 1 for non-overlapping, m for overlapping estimators. n: phase points.
double GreenhallEdf(int alpha, int d, double m, bool modified, bool overlapping, double n) {
  constexpr double kJmax = 100.0;
  const double f = modified ? 1.0 : m;
  const double s = overlapping ? m : 1.0;
  const double l = m / f + m * d;
  if (n < l) return kNaN;
  const double big_m = 1.0 + std::floor(s * (n - l) / m);
  const double j = std::min(big_m, (d + 1) * s);
  const double r = big_m / s;
  const int row = 2 - alpha;
  auto inv_basic = [&](double jj, double mm, double ss, double ff, double scale_f) {
    const double z0 = Sz(0.0, scale_f, alpha, d);
    return BasicSum(jj, mm, ss, ff, alpha, d) / (z0 * z0 * mm);
  };
  double inv_edf = kNaN;
  if (modified) {
    if (j <= kJmax) {
      inv_edf = inv_basic(j, big_m, s, 1.0, 1.0);
    } else if (r > d + 1) {
      const double a0 = kTable1[row][d - 1][0], a1 = kTable1[row][d - 1][1];
      inv_edf = (a0 - a1 / r) / r;
    } else {
      inv_edf = inv_basic(kJmax, kJmax, kJmax / r, 1.0, 1.0);
    }
  } else if (alpha <= 0) {
    if (j <= kJmax) {
      // Large m: the continuous limit avoids the cancellation in F^2 (2 sw(t) - ...).
      const double fm = m * (d + 1) <= kJmax ? m : kInf;
      inv_edf = inv_basic(j, big_m, s, fm, fm);
    } else if (r > d + 1) {
      const double a0 = kTable2[row][d - 1][0], a1 = kTable2[row][d - 1][1];
      inv_edf = (a0 - a1 / r) / r;
    } else {
      inv_edf = inv_basic(kJmax, kJmax, kJmax / r, kInf, kInf);
    }
  } else if (alpha == 1) {
    if (j <= kJmax) {
      inv_edf = inv_basic(j, big_m, s, m, m);
    } else {
      const double b = kTable3[d - 1][0] + kTable3[d - 1][1] * std::log(m);
      if (r > d + 1) {
        const double a0 = kTable2[row][d - 1][0], a1 = kTable2[row][d - 1][1];
        inv_edf = (a0 - a1 / r) / (b * b * r);
      } else {
        const double mp = kJmax / r;
        inv_edf = BasicSum(kJmax, kJmax, mp, mp, 1, d) / (b * b * kJmax);
      }
    }
  } else {  // alpha == 2, unmodified
    const double k = std::ceil(r);
    if (k <= d) {
      // Few terms: the exact basic sum (J = M here, at most d + 1 terms' worth).
      inv_edf = inv_basic(j, big_m, s, m, m);
    } else {
      double a0 = 1.0;  // C(4d, 2d) / C(2d, d)^2
      for (int i = 1; i <= 2 * d; ++i) a0 *= static_cast<double>(2 * d + i) / i;
      double c = 1.0;
      for (int i = 1; i <= d; ++i) c *= static_cast<double>(d + i) / i;
      a0 /= c * c;
      inv_edf = (a0 - (d / 2.0) / r) / big_m;
    }
  }
  return 1.0 / inv_edf;
}

Eigen::Vector3d PolyFromSums(Eigen::Index n, int deg, double s0, double s1, double s2);

// Least-squares polynomial (degree 1 or 2) of z_i, i = 0..n-1, on t = (i - c) / c with
// c = (n - 1) / 2; returns the coefficients. The moments of t are closed forms (odd ones vanish),
// so the pass over the data only accumulates sum t^k z.
template <class Z>
Eigen::Vector3d PolyFit(Eigen::Index n, int deg, const Z& z) {
  const double nd = static_cast<double>(n);
  const double c = 0.5 * (nd - 1.0), inv_c = 1.0 / c;
  double s0 = 0.0, s1 = 0.0, s2 = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * inv_c - 1.0, v = z(i);
    s0 += v;
    s1 += t * v;
    s2 += t * t * v;
  }
  return PolyFromSums(n, deg, s0, s1, s2);
}

// The coefficients of PolyFit from its sums s0 = sum z, s1 = sum t z, s2 = sum t^2 z.
Eigen::Vector3d PolyFromSums(Eigen::Index n, int deg, double s0, double s1, double s2) {
  const double nd = static_cast<double>(n);
  const double c = 0.5 * (nd - 1.0), inv_c = 1.0 / c;
  // sum (i - c)^2 = n (n^2 - 1) / 12, sum (i - c)^4 = n (n^2 - 1) (3 n^2 - 7) / 240.
  const double t2 = nd * (nd * nd - 1.0) / 12.0 * inv_c * inv_c;
  const double t4 = nd * (nd * nd - 1.0) * (3.0 * nd * nd - 7.0) / 240.0 * std::pow(inv_c, 4);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  p[1] = s1 / t2;
  if (deg == 1) {
    p[0] = s0 / nd;
  } else {
    // [n t2; t2 t4] [p0; p2] = [s0; s2]
    const double det = nd * t4 - t2 * t2;
    p[0] = (t4 * s0 - t2 * s2) / det;
    p[2] = (nd * s2 - t2 * s0) / det;
  }
  return p;
}

double Lag1FromSums(Eigen::Index n, double s1, double s2, double lag, double first, double last);

// Lag-1 autocorrelation of r_i = z(i) - poly(t_i), in one pass over the samples.
template <class Z>
double Lag1OfResidual(Eigen::Index n, const Eigen::Vector3d& p, const Z& z) {
  const double inv_c = 2.0 / static_cast<double>(n - 1);
  auto r = [&](Eigen::Index i) {
    const double t = static_cast<double>(i) * inv_c - 1.0;
    return z(i) - (p[0] + t * (p[1] + t * p[2]));
  };
  double s1 = 0.0, s2 = 0.0, lag = 0.0, prev = r(0);
  const double first = prev;
  s1 += prev;
  s2 += prev * prev;
  for (Eigen::Index i = 1; i < n; ++i) {
    const double v = r(i);
    s1 += v;
    s2 += v * v;
    lag += prev * v;
    prev = v;
  }
  return Lag1FromSums(n, s1, s2, lag, first, prev);
}

// Lag1OfResidual from its sums: s1 = sum r, s2 = sum r^2, lag = sum r_i r_{i+1}, first = r_0,
// last = r_{n-1}.
double Lag1FromSums(Eigen::Index n, double s1, double s2, double lag, double first, double last) {
  const double nd = static_cast<double>(n), mean = s1 / nd;
  const double den = s2 - nd * mean * mean;
  const double num = lag - mean * (2.0 * s1 - first - last) + (nd - 1.0) * mean * mean;
  return den > 0.0 ? num / den : 0.0;
}

// The noise type from the lag-1 autocorrelation rho of the series differenced d times.
int AlphaFromRho(double rho, int d, bool rate, int dmax) {
  int alpha = -static_cast<int>(std::nearbyint(2.0 * rho)) - 2 * d;
  if (!rate) alpha += 2;
  return std::clamp(alpha, dmax == 2 ? -2 : -4, 2);
}

}  // namespace

double EquivalentDof(Deviation dev, int alpha, std::int64_t m, Eigen::Index n_phase) {
  const double md = static_cast<double>(m);
  const double n = static_cast<double>(n_phase);
  switch (dev) {
    case Deviation::kAdev:
      return GreenhallEdf(alpha, 2, md, false, false, n);
    case Deviation::kOadev:
      return GreenhallEdf(alpha, 2, md, false, true, n);
    case Deviation::kMdev:
    case Deviation::kTdev:
      return GreenhallEdf(alpha, 2, md, true, true, n);
    case Deviation::kHdev:
      return GreenhallEdf(alpha, 3, md, false, false, n);
    case Deviation::kOhdev:
      return GreenhallEdf(alpha, 3, md, false, true, n);
    case Deviation::kTotdev: {
      // NIST SP 1065 table 7: edf = b (T / tau) - c, T = record length (N - 1) tau0.
      static constexpr double kBc[3][2] = {{1.50, 0.0}, {1.17, 0.22}, {0.93, 0.36}};
      if (alpha <= 0 && alpha >= -2) return kBc[-alpha][0] * ((n - 1.0) / md) - kBc[-alpha][1];
      // Phase noise (table 7 has no row): the simple OADEV formulas of SP 1065 table 5
      // (Howe, Allan, Barnes 1981), which is what Stable32's intervals imply.
      if (alpha == 2) return (n + 1.0) * (n - 2.0 * md) / (2.0 * (n - md));
      if (alpha == 1)
        return std::exp(std::sqrt(std::log((n - 1.0) / (2.0 * md)) *
                                  std::log((2.0 * md + 1.0) * (n - 1.0) / 4.0)));
      return GreenhallEdf(alpha, 2, md, false, true, n);
    }
  }
  return kNaN;
}

double RegularizedGammaP(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return kNaN;
  if (x == 0.0) return 0.0;
  if (x == kInf) return 1.0;
  const double log_prefactor = -x + a * std::log(x) - std::lgamma(a);
  const int max_iter = 1000 + static_cast<int>(20.0 * std::sqrt(a));
  constexpr double kEps = 1e-16;
  if (x < a + 1.0) {
    // Series: P = e^-x x^a / Gamma(a+1) * sum x^n / ((a+1)...(a+n)).
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < max_iter; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * kEps) break;
    }
    return std::min(1.0, sum * std::exp(log_prefactor));
  }
  // Continued fraction for Q (modified Lentz).
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < max_iter; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::max(0.0, 1.0 - std::exp(log_prefactor) * h);
}

double ChiSquareQuantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0)) return kNaN;
  // Standard normal quantile by bisection on erfc (64 halvings of [-40, 40]: below 1e-17).
  // Every tau of a curve asks for the same two levels, so the last two are kept per thread.
  thread_local double cached_p[2] = {-1.0, -1.0}, cached_z[2] = {0.0, 0.0};
  double z;
  if (p == cached_p[0]) {
    z = cached_z[0];
  } else if (p == cached_p[1]) {
    z = cached_z[1];
  } else {
    double zlo = -40.0, zhi = 40.0;
    for (int i = 0; i < 64; ++i) {
      const double mid = 0.5 * (zlo + zhi);
      if (0.5 * std::erfc(-mid / std::numbers::sqrt2) < p)
        zlo = mid;
      else
        zhi = mid;
    }
    z = 0.5 * (zlo + zhi);
    cached_p[1] = cached_p[0];
    cached_z[1] = cached_z[0];
    cached_p[0] = p;
    cached_z[0] = z;
  }
  // Wilson-Hilferty; above kWilsonHilfertyDof its relative error is below 1e-6 (unit test), and
  // the series below would need O(sqrt(dof)) terms per step.
  const double h = 2.0 / (9.0 * dof);
  double x = dof * std::pow(std::max(1e-10, 1.0 - h + z * std::sqrt(h)), 3);
  if (dof > kWilsonHilfertyDof) return x;
  const double a = 0.5 * dof;
  double lo = 0.0, hi = kInf;
  for (int it = 0; it < 200; ++it) {
    const double f = RegularizedGammaP(a, 0.5 * x) - p;
    if (f < 0.0)
      lo = x;
    else
      hi = x;
    const double log_density =
        (a - 1.0) * std::log(0.5 * x) - 0.5 * x - std::lgamma(a) - std::log(2.0);
    const double density = std::exp(log_density);
    double next = density > 0.0 ? x - f / density : kNaN;
    if (!(next > lo && next < hi)) next = hi == kInf ? 2.0 * x + 1.0 : 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-14 * x) return next;
    x = next;
  }
  return x;
}

void ConfidenceInterval(double dev, double edf, double confidence, double* lo, double* hi) {
  if (!(edf > 0.0) || !std::isfinite(edf)) {
    *lo = *hi = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  const double tail = 0.5 * (1.0 - confidence);
  const double chi_hi = ChiSquareQuantile(1.0 - tail, edf);
  const double chi_lo = ChiSquareQuantile(tail, edf);
  *lo = dev * std::sqrt(edf / chi_hi);
  *hi = dev * std::sqrt(edf / chi_lo);
}

std::optional<int> IdentifyAlpha(const Eigen::Ref<const Eigen::VectorXd>& phase, std::int64_t m,
                                 DataType type, int dmax) {
  const Eigen::Index n = phase.size();
  const bool rate = type == DataType::kRate;
  // Rate data: the m-sample averages (differences of the integrated angle), linear trend removed.
  // Angle data: the phase decimated by m, quadratic trend removed (Riley & Greenhall 2004).
  const Eigen::Index k = rate ? (n - 1) / m : (n - 1) / m + 1;
  if (k < kMinPoints) return std::nullopt;
  const int deg = rate ? 1 : 2;
  auto sample = [&](Eigen::Index i) {
    return rate ? phase[(i + 1) * m] - phase[i * m] : phase[i * m];
  };
  const Eigen::Vector3d poly = PolyFit(k, deg, sample);
  auto finish = [&](double rho, int d) { return AlphaFromRho(rho, d, rate, dmax); };
  double r1 = Lag1OfResidual(k, poly, sample);
  double rho = r1 / (1.0 + r1);
  if (rho < 0.25 || dmax <= 0) return finish(rho, 0);
  // Strongly correlated: difference the detrended series until white enough (or dmax).
  Eigen::VectorXd z(k);
  const double inv_c = 2.0 / static_cast<double>(k - 1);
  for (Eigen::Index i = 0; i < k; ++i) {
    const double t = static_cast<double>(i) * inv_c - 1.0;
    z[i] = sample(i) - (poly[0] + t * (poly[1] + t * poly[2]));
  }
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  for (int d = 1;; ++d) {
    for (Eigen::Index i = 0; i + d < k; ++i) z[i] = z[i + 1] - z[i];
    const Eigen::Index len = k - d;
    r1 = Lag1OfResidual(len, zero, [&](Eigen::Index i) { return z[i]; });
    rho = r1 / (1.0 + r1);
    if (rho < 0.25 || d >= dmax) return finish(rho, d);
  }
}

namespace internal {
namespace {

// One factor's state in IdentifyAlphas' sweeps: its next point and its running sums.
struct AlphaScan {
  std::int64_t m;
  Eigen::Index k;  // points
  Eigen::Index next = 0;
  double s0 = 0.0, s1 = 0.0, s2 = 0.0;  // PolyFit's sums, then Lag1OfResidual's
  double lag = 0.0, first = 0.0, prev = 0.0;
  Eigen::Vector3d poly = Eigen::Vector3d::Zero();
};

// Calls take(scan, to) for every scan after each chunk of the phase (n points), `to` being the
// number of the scan's points whose last phase index, (i + 1) m (rate) or i m (angle), lies in
// the chunks so far.
template <class Take>
void Sweep(std::vector<AlphaScan>& scans, Eigen::Index n, bool rate, Take&& take) {
  for (Eigen::Index end = std::min(n, kScanChunk);; end = std::min(n, end + kScanChunk)) {
    for (AlphaScan& sc : scans)
      take(sc, std::min<Eigen::Index>(sc.k, (end - 1) / sc.m + (rate ? 0 : 1)));
    if (end == n) break;
  }
}

// PolyFit's sums over points [sc.next, to) of the scan's series of the phase x (kRate: rate data).
template <bool kRate>
void AddTrendSums(const double* x, AlphaScan& sc, Eigen::Index to) {
  const std::int64_t m = sc.m;
  const double inv_c = 1.0 / (0.5 * (static_cast<double>(sc.k) - 1.0));  // as PolyFit
  double s0 = sc.s0, s1 = sc.s1, s2 = sc.s2;
  for (Eigen::Index i = sc.next; i < to; ++i) {
    const double t = static_cast<double>(i) * inv_c - 1.0;
    const double v = kRate ? x[(i + 1) * m] - x[i * m] : x[i * m];
    s0 += v;
    s1 += t * v;
    s2 += t * t * v;
  }
  sc.s0 = s0, sc.s1 = s1, sc.s2 = s2;
  sc.next = to;
}

// Lag1OfResidual's sums over points [sc.next, to) of the residual from the scan's trend sc.poly.
template <bool kRate>
void AddLagSums(const double* x, AlphaScan& sc, Eigen::Index to) {
  const std::int64_t m = sc.m;
  const Eigen::Vector3d& p = sc.poly;
  const double inv_c = 2.0 / static_cast<double>(sc.k - 1);  // as Lag1OfResidual
  auto r = [&](Eigen::Index i) {
    const double t = static_cast<double>(i) * inv_c - 1.0;
    return (kRate ? x[(i + 1) * m] - x[i * m] : x[i * m]) - (p[0] + t * (p[1] + t * p[2]));
  };
  Eigen::Index i = sc.next;
  if (i >= to) return;
  double s1 = sc.s1, s2 = sc.s2, lag = sc.lag, prev = sc.prev;
  if (i == 0) {
    prev = sc.first = r(0);
    s1 += prev;
    s2 += prev * prev;
    ++i;
  }
  for (; i < to; ++i) {
    const double v = r(i);
    s1 += v;
    s2 += v * v;
    lag += prev * v;
    prev = v;
  }
  sc.s1 = s1, sc.s2 = s2, sc.lag = lag, sc.prev = prev;
  sc.next = to;
}

}  // namespace

std::vector<std::optional<int>> IdentifyAlphas(const Eigen::Ref<const Eigen::VectorXd>& phase,
                                               const std::vector<std::int64_t>& ms, DataType type,
                                               int dmax) {
  // IdentifyAlpha's two passes (the trend fit, then the lag-1 autocorrelation of the residual)
  // for every factor at once: each pass is one sweep over the phase in chunks, every factor
  // taking the points that end in the chunk, so the phase comes from memory twice in all instead
  // of twice per factor (strided, a cache line per point from m = 8 on). Each factor's sums run
  // over its points in the same order as in IdentifyAlpha, so the bits are the same.
  const Eigen::Index n = phase.size();
  const bool rate = type == DataType::kRate;
  const double* x = phase.data();
  std::vector<std::optional<int>> alpha(ms.size());
  std::vector<AlphaScan> scans;
  std::vector<size_t> index;  // scans[j] is factor ms[index[j]]
  for (size_t j = 0; j < ms.size(); ++j) {
    const Eigen::Index k = rate ? (n - 1) / ms[j] : (n - 1) / ms[j] + 1;
    if (k < kMinPoints) continue;
    scans.push_back({.m = ms[j], .k = k});
    index.push_back(j);
  }
  // The data type as a template argument: each sweep's loops compile for one type.
  if (rate)
    Sweep(scans, n, rate, [&](AlphaScan& sc, Eigen::Index to) { AddTrendSums<true>(x, sc, to); });
  else
    Sweep(scans, n, rate, [&](AlphaScan& sc, Eigen::Index to) { AddTrendSums<false>(x, sc, to); });
  for (AlphaScan& sc : scans) {
    sc.poly = PolyFromSums(sc.k, rate ? 1 : 2, sc.s0, sc.s1, sc.s2);
    sc.next = 0;
    sc.s1 = sc.s2 = 0.0;
  }
  if (rate)
    Sweep(scans, n, rate, [&](AlphaScan& sc, Eigen::Index to) { AddLagSums<true>(x, sc, to); });
  else
    Sweep(scans, n, rate, [&](AlphaScan& sc, Eigen::Index to) { AddLagSums<false>(x, sc, to); });
  for (size_t j = 0; j < scans.size(); ++j) {
    const AlphaScan& sc = scans[j];
    const double r1 = Lag1FromSums(sc.k, sc.s1, sc.s2, sc.lag, sc.first, sc.prev);
    const double rho = r1 / (1.0 + r1);
    // Strongly correlated: the differencing stages, rare at most factors of a gyro's curve.
    alpha[index[j]] = rho < 0.25 || dmax <= 0 ? AlphaFromRho(rho, 0, rate, dmax)
                                              : IdentifyAlpha(phase, sc.m, type, dmax);
  }
  return alpha;
}

}  // namespace internal
}  // namespace gyrodrift::allan
