#include "decomposition/sifting.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace gyrodrift::decomposition::internal {
namespace {

constexpr int kNbSym = 2;  // mirrored extrema per end (emd.m's NBSYM)

// Plateau extrema of emd.m's extr(): a run of equal samples between a rise and a fall is one
// extremum at its middle sample (MATLAB round: halves go up). Runs touching either end are
// ignored. Appends 0-based indices, in increasing order, to mins / maxs.
template <class Sink>
void PlateauExtrema(const double* x, Eigen::Index n, Sink&& sink) {
  Eigen::Index j = 0;
  const Eigen::Index nd = n - 1;  // number of differences
  while (j < nd) {
    if (x[j + 1] - x[j] != 0.0) {
      ++j;
      continue;
    }
    const Eigen::Index a = j;  // first zero difference of the run
    while (j < nd && x[j + 1] - x[j] == 0.0) ++j;
    const Eigen::Index b = j - 1;  // last zero difference
    if (a == 0 || b == nd - 1) continue;
    const double before = x[a] - x[a - 1];
    const double after = x[b + 2] - x[b + 1];
    const Eigen::Index middle = (a + b + 2) / 2;
    if (before > 0.0) {
      if (after < 0.0) sink(middle, /*is_max=*/true);
    } else if (after > 0.0) {
      sink(middle, /*is_max=*/false);
    }
  }
}

// Number of runs of exact zeros (emd.m counts each run once as a zero crossing).
int ZeroRuns(const double* x, Eigen::Index n) {
  int runs = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (x[i] == 0.0 && (i == 0 || x[i - 1] != 0.0)) ++runs;
  }
  return runs;
}

// Strict extrema and zero crossings in one branch-light pass; plateaus and exact zeros flagged.
struct StrictScan {
  int minima = 0, maxima = 0, zero_crossings = 0;
  bool flat = false, zero = false;
};

template <bool kStore>
StrictScan ScanStrict(const double* x, Eigen::Index n, int* indmin, int* indmax) {
  StrictScan s;
  if (n < 2) return s;
  double d0 = x[1] - x[0];
  bool flat = d0 == 0.0;
  bool zero = x[0] == 0.0 || x[1] == 0.0;
  int zc = x[0] * x[1] < 0.0;
  int nmin = 0, nmax = 0;
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    const double d1 = x[i + 1] - x[i];
    const bool is_ext = d0 * d1 < 0.0;
    if constexpr (kStore) {
      indmin[nmin] = static_cast<int>(i);
      indmax[nmax] = static_cast<int>(i);
    }
    nmin += is_ext & (d0 < 0.0);
    nmax += is_ext & (d0 > 0.0);
    flat |= d1 == 0.0;
    zero |= x[i + 1] == 0.0;
    zc += x[i] * x[i + 1] < 0.0;
    d0 = d1;
  }
  s.minima = nmin;
  s.maxima = nmax;
  s.zero_crossings = zc;
  s.flat = flat;
  s.zero = zero;
  return s;
}

}  // namespace

ExtremaCounts CountExtrema(const double* x, Eigen::Index n) {
  const StrictScan s = ScanStrict<false>(x, n, nullptr, nullptr);
  ExtremaCounts c{s.minima, s.maxima, s.zero_crossings};
  if (s.flat) {
    PlateauExtrema(x, n, [&](Eigen::Index, bool is_max) { ++(is_max ? c.maxima : c.minima); });
  }
  if (s.zero) c.zero_crossings += ZeroRuns(x, n);
  return c;
}

Sifter::Sifter(Eigen::Index n, const SiftingOptions& options)
    : n_(n), options_(options), max_sifts_(options.EffectiveMaxSifts()) {
  const size_t size = static_cast<size_t>(n);
  indmin_.resize(size + 2);
  indmax_.resize(size + 2);
  const size_t nodes = size + 2 * kNbSym + 4;
  for (auto* v : {&tmin_, &zmin_, &tmax_, &zmax_}) v->reserve(nodes);
  for (auto* v : {&slope_, &diag_, &rhs_}) v->resize(nodes);
  h_.resize(n);
  next_.resize(n);
  env_min_.resize(n);
  env_max_.resize(n);
}

ExtremaCounts Sifter::FindExtrema(const double* h) {
  const StrictScan s = ScanStrict<true>(h, n_, indmin_.data(), indmax_.data());
  ExtremaCounts c{s.minima, s.maxima, s.zero_crossings};
  if (s.flat) {
    // Merge the plateau extrema into the strict ones, from the back, in place.
    int extra_min = 0, extra_max = 0;
    PlateauExtrema(h, n_, [&](Eigen::Index, bool is_max) { ++(is_max ? extra_max : extra_min); });
    if (extra_min + extra_max > 0) {
      // Collect plateau indices at the tail of the arrays (capacity n + 2 suffices: extrema are
      // distinct interior samples).
      int pm = 0, px = 0;
      const size_t cap = indmin_.size();
      PlateauExtrema(h, n_, [&](Eigen::Index i, bool is_max) {
        if (is_max) {
          indmax_[cap - static_cast<size_t>(extra_max) + static_cast<size_t>(px++)] = static_cast<int>(i);
        } else {
          indmin_[cap - static_cast<size_t>(extra_min) + static_cast<size_t>(pm++)] = static_cast<int>(i);
        }
      });
      auto merge_back = [cap](std::vector<int>& ind, int strict, int extra) {
        int a = strict - 1, b = extra - 1, out = strict + extra - 1;
        const size_t base = cap - static_cast<size_t>(extra);
        while (b >= 0) {
          if (a >= 0 && ind[static_cast<size_t>(a)] > ind[base + static_cast<size_t>(b)]) {
            ind[static_cast<size_t>(out--)] = ind[static_cast<size_t>(a--)];
          } else {
            ind[static_cast<size_t>(out--)] = ind[base + static_cast<size_t>(b--)];
          }
        }
      };
      merge_back(indmin_, c.minima, extra_min);
      merge_back(indmax_, c.maxima, extra_max);
      c.minima += extra_min;
      c.maxima += extra_max;
    }
  }
  if (s.zero) c.zero_crossings += ZeroRuns(h, n_);
  return c;
}

bool Sifter::BoundaryConditions(const double* h) {
  // Counts are the current FindExtrema result, stored by the caller in nmin_/nmax_.
  const int nmin = nmin_, nmax = nmax_;
  if (nmin + nmax < 3 || nmin == 0 || nmax == 0) return false;
  const int* imin = indmin_.data();
  const int* imax = indmax_.data();
  const int last = static_cast<int>(n_) - 1;

  // Index lists are short (<= nbsym + 1); fliplr(ind(from:to)) in 0-based half-open form.
  struct List {
    int v[kNbSym + 2];
    int size = 0;
    void Clear() { size = 0; }
    void Push(int i) { v[size++] = i; }
    void PushReversed(const int* ind, int from, int to) {
      for (int k = to - 1; k >= from; --k) Push(ind[k]);
    }
  };
  List lmin, lmax, rmin, rmax;
  int lsym, rsym;

  if (imax[0] < imin[0]) {
    if (h[0] > h[imin[0]]) {
      lmax.PushReversed(imax, 1, std::min(nmax, kNbSym + 1));
      lmin.PushReversed(imin, 0, std::min(nmin, kNbSym));
      lsym = imax[0];
    } else {
      lmax.PushReversed(imax, 0, std::min(nmax, kNbSym));
      lmin.PushReversed(imin, 0, std::min(nmin, kNbSym - 1));
      lmin.Push(0);
      lsym = 0;
    }
  } else {
    if (h[0] < h[imax[0]]) {
      lmax.PushReversed(imax, 0, std::min(nmax, kNbSym));
      lmin.PushReversed(imin, 1, std::min(nmin, kNbSym + 1));
      lsym = imin[0];
    } else {
      lmax.PushReversed(imax, 0, std::min(nmax, kNbSym - 1));
      lmax.Push(0);
      lmin.PushReversed(imin, 0, std::min(nmin, kNbSym));
      lsym = 0;
    }
  }
  if (imax[nmax - 1] < imin[nmin - 1]) {
    if (h[last] < h[imax[nmax - 1]]) {
      rmax.PushReversed(imax, std::max(nmax - kNbSym, 0), nmax);
      rmin.PushReversed(imin, std::max(nmin - kNbSym - 1, 0), nmin - 1);
      rsym = imin[nmin - 1];
    } else {
      rmax.Push(last);
      rmax.PushReversed(imax, std::max(nmax - kNbSym + 1, 0), nmax);
      rmin.PushReversed(imin, std::max(nmin - kNbSym, 0), nmin);
      rsym = last;
    }
  } else {
    if (h[last] > h[imin[nmin - 1]]) {
      rmax.PushReversed(imax, std::max(nmax - kNbSym - 1, 0), nmax - 1);
      rmin.PushReversed(imin, std::max(nmin - kNbSym, 0), nmin);
      rsym = imax[nmax - 1];
    } else {
      rmax.PushReversed(imax, std::max(nmax - kNbSym, 0), nmax);
      rmin.Push(last);
      rmin.PushReversed(imin, std::max(nmin - kNbSym + 1, 0), nmin);
      rsym = last;
    }
  }

  // Times are t = index + 1; a node mirrored about sample s sits at 2 t(s) - t(node).
  auto mirrored = [](int sym, int node) { return 2.0 * (sym + 1) - (node + 1); };
  const double t_first = 1.0, t_last = static_cast<double>(n_);

  // emd.m: "in case symmetrized parts do not extend enough". Indexing an empty list there is an
  // error in MATLAB (caught as "stop sifting"), hence the early returns.
  if (lmin.size == 0) return false;
  bool left_short = mirrored(lsym, lmin.v[0]) > t_first;
  if (!left_short) {
    if (lmax.size == 0) return false;
    left_short = mirrored(lsym, lmax.v[0]) > t_first;
  }
  if (left_short) {
    if (lsym == imax[0]) {
      lmax.Clear();
      lmax.PushReversed(imax, 0, std::min(nmax, kNbSym));
    } else {
      lmin.Clear();
      lmin.PushReversed(imin, 0, std::min(nmin, kNbSym));
    }
    if (lsym == 0) return false;
    lsym = 0;
  }
  if (rmin.size == 0) return false;
  bool right_short = mirrored(rsym, rmin.v[rmin.size - 1]) < t_last;
  if (!right_short) {
    if (rmax.size == 0) return false;
    right_short = mirrored(rsym, rmax.v[rmax.size - 1]) < t_last;
  }
  if (right_short) {
    if (rsym == imax[nmax - 1]) {
      rmax.Clear();
      rmax.PushReversed(imax, std::max(nmax - kNbSym, 0), nmax);
    } else {
      rmin.Clear();
      rmin.PushReversed(imin, std::max(nmin - kNbSym, 0), nmin);
    }
    if (rsym == last) return false;
    rsym = last;
  }

  auto assemble = [&](const List& left, const int* interior, int count, const List& right,
                      std::vector<double>& t, std::vector<double>& z) {
    t.clear();
    z.clear();
    for (int k = 0; k < left.size; ++k) {
      t.push_back(mirrored(lsym, left.v[k]));
      z.push_back(h[left.v[k]]);
    }
    for (int k = 0; k < count; ++k) {
      t.push_back(interior[k] + 1.0);
      z.push_back(h[interior[k]]);
    }
    for (int k = 0; k < right.size; ++k) {
      t.push_back(mirrored(rsym, right.v[k]));
      z.push_back(h[right.v[k]]);
    }
    if (t.size() < 2) return false;
    for (size_t k = 1; k < t.size(); ++k) {
      if (!(t[k] > t[k - 1])) return false;  // interp1 needs distinct increasing nodes
    }
    return true;
  };
  return assemble(lmin, imin, nmin, rmin, tmin_, zmin_) &&
         assemble(lmax, imax, nmax, rmax, tmax_, zmax_);
}

void Sifter::EvaluateSpline(const std::vector<double>& t, const std::vector<double>& y,
                            double* out) {
  const size_t m = t.size();
  const Eigen::Index n = n_;
  if (m == 2) {  // straight line (MATLAB spline with 2 nodes)
    const double slope = (y[1] - y[0]) / (t[1] - t[0]);
    for (Eigen::Index i = 0; i < n; ++i) out[i] = slope * ((i + 1) - t[0]) + y[0];
    return;
  }
  if (m == 3) {  // the interpolating parabola
    const double dx0 = t[1] - t[0];
    const double dd0 = (y[1] - y[0]) / dx0;
    const double dd1 = (y[2] - y[1]) / (t[2] - t[1]);
    const double c2 = (dd1 - dd0) / (t[2] - t[0]);
    const double c1 = dd0 - c2 * dx0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double h = (i + 1) - t[0];
      out[i] = (c2 * h + c1) * h + y[0];
    }
    return;
  }
  // Not-a-knot slopes (MATLAB spline.m), tridiagonal, solved by forward elimination and back
  // substitution. Row j: sub * s[j-1] + diag * s[j] + sup * s[j+1] = rhs.
  double* s = slope_.data();
  double* diag = diag_.data();
  double* rhs = rhs_.data();
  auto dx = [&](size_t j) { return t[j + 1] - t[j]; };
  auto dd = [&](size_t j) { return (y[j + 1] - y[j]) / (t[j + 1] - t[j]); };
  const double x31 = t[2] - t[0];
  const double xn = t[m - 1] - t[m - 3];
  // Row 0: dx1 s0 + x31 s1.
  diag[0] = dx(1);
  rhs[0] = ((dx(0) + 2 * x31) * dx(1) * dd(0) + dx(0) * dx(0) * dd(1)) / x31;
  double sup_prev = x31;
  for (size_t j = 1; j < m; ++j) {
    double sub, dj, sup, r;
    if (j < m - 1) {
      sub = dx(j);
      dj = 2 * (dx(j) + dx(j - 1));
      sup = dx(j - 1);
      r = 3 * (dx(j) * dd(j - 1) + dx(j - 1) * dd(j));
    } else {
      sub = xn;
      dj = dx(m - 3);
      sup = 0.0;
      r = (dx(m - 2) * dx(m - 2) * dd(m - 3) + (2 * xn + dx(m - 2)) * dx(m - 3) * dd(m - 2)) / xn;
    }
    const double w = sub / diag[j - 1];
    diag[j] = dj - w * sup_prev;
    rhs[j] = r - w * rhs[j - 1];
    // Keep the super-diagonal for back substitution in s[] (overwritten below, read first).
    s[j - 1] = sup_prev;
    sup_prev = sup;
  }
  // Back substitution: s[j-1] currently holds row j-1's super-diagonal.
  double next = rhs[m - 1] / diag[m - 1];
  for (size_t j = m - 1; j-- > 0;) {
    const double value = (rhs[j] - s[j] * next) / diag[j];
    s[j + 1] = next;
    next = value;
  }
  s[0] = next;

  // Piecewise cubic Hermite (MATLAB pwch + ppval Horner order), interval by interval.
  Eigen::Index i = 0;
  for (size_t j = 0; j + 1 < m && i < n; ++j) {
    Eigen::Index end = n;
    if (j + 2 < m) {
      end = std::clamp(static_cast<Eigen::Index>(std::ceil(t[j + 1])) - 1, i, n);
    }
    const double h_len = dx(j);
    const double divdif = (y[j + 1] - y[j]) / h_len;
    const double dzzdx = (divdif - s[j]) / h_len;
    const double dzdxdx = (s[j + 1] - divdif) / h_len;
    const double c1 = (dzdxdx - dzzdx) / h_len;
    const double c2 = 2 * dzzdx - dzdxdx;
    const double c3 = s[j];
    const double c4 = y[j];
    const double tj = t[j];
    for (; i < end; ++i) {
      const double h = static_cast<double>(i + 1) - tj;
      out[i] = ((h * c1 + c2) * h + c3) * h + c4;
    }
  }
}

bool Sifter::EnvelopeNodes(const double* x, std::vector<double>* tmin, std::vector<double>* zmin,
                           std::vector<double>* tmax, std::vector<double>* zmax) {
  const ExtremaCounts c = FindExtrema(x);
  nmin_ = c.minima;
  nmax_ = c.maxima;
  if (!BoundaryConditions(x)) return false;
  *tmin = tmin_;
  *zmin = zmin_;
  *tmax = tmax_;
  *zmax = zmax_;
  return true;
}

bool Sifter::MeanAndAmplitude(const double* x, double* mean, double* amplitude) {
  const ExtremaCounts c = FindExtrema(x);
  nmin_ = c.minima;
  nmax_ = c.maxima;
  if (!BoundaryConditions(x)) return false;
  EvaluateSpline(tmin_, zmin_, env_min_.data());
  EvaluateSpline(tmax_, zmax_, env_max_.data());
  for (Eigen::Index i = 0; i < n_; ++i) {
    mean[i] = (env_min_[i] + env_max_[i]) / 2;
    amplitude[i] = std::abs(env_max_[i] - env_min_[i]) / 2;
  }
  return true;
}

SiftOutcome Sifter::ExtractImf(const double* x, double* imf) {
  SiftOutcome outcome;
  std::copy(x, x + n_, h_.data());
  ExtremaCounts counts = FindExtrema(h_.data());
  if (counts.extrema() < 3) {
    outcome.extracted = false;
    return outcome;
  }
  const StopRule rule = options_.stop_rule;
  const double n_double = static_cast<double>(n_);
  int stable = 0;
  ExtremaCounts previous = counts;
  for (;;) {
    if (rule == StopRule::kSNumber && outcome.sifts > 0) {
      const bool same = counts.extrema() == previous.extrema() &&
                        counts.zero_crossings == previous.zero_crossings;
      const bool imf_like = std::abs(counts.extrema() - counts.zero_crossings) <= 1;
      stable = (same && imf_like) ? stable + 1 : 0;
      previous = counts;
      if (stable >= options_.s_number) break;
    }
    if (rule == StopRule::kFixed && outcome.sifts >= options_.fixed_sifts) break;

    nmin_ = counts.minima;
    nmax_ = counts.maxima;
    if (counts.extrema() < 3 || !BoundaryConditions(h_.data())) break;  // emd.m's catch: stop
    EvaluateSpline(tmin_, zmin_, env_min_.data());
    EvaluateSpline(tmax_, zmax_, env_max_.data());

    const double* h = h_.data();
    const double* lo = env_min_.data();
    const double* hi = env_max_.data();
    double* next = next_.data();
    bool stop = false;
    if (rule == StopRule::kRilling) {
      const double t1 = options_.rilling_threshold1, t2 = options_.rilling_threshold2;
      Eigen::Index above1 = 0;
      bool above2 = false;
      for (Eigen::Index i = 0; i < n_; ++i) {
        const double mean = (lo[i] + hi[i]) / 2;
        const double amplitude = std::abs(hi[i] - lo[i]) / 2;
        const double ratio = std::abs(mean) / amplitude;
        above1 += ratio > t1;
        above2 |= ratio > t2;
        next[i] = h[i] - mean;
      }
      const bool keep_sifting = static_cast<double>(above1) / n_double > options_.rilling_tolerance ||
                                above2;
      stop = !keep_sifting && std::abs(counts.zero_crossings - counts.extrema()) <= 1;
      if (stop) break;
    } else if (rule == StopRule::kCauchySd) {
      double mean_energy = 0.0, energy = 0.0;
      for (Eigen::Index i = 0; i < n_; ++i) {
        const double mean = (lo[i] + hi[i]) / 2;
        mean_energy += mean * mean;
        energy += h[i] * h[i];
        next[i] = h[i] - mean;
      }
      stop = energy == 0.0 || mean_energy / energy < options_.sd_threshold;
    } else {
      for (Eigen::Index i = 0; i < n_; ++i) next[i] = h[i] - (lo[i] + hi[i]) / 2;
    }
    if (outcome.sifts >= max_sifts_) {
      outcome.cap_hit = true;
      break;
    }
    std::swap(h_, next_);
    ++outcome.sifts;
    if (stop) break;  // Cauchy SD: the sift that met the threshold is kept
    counts = FindExtrema(h_.data());
  }
  std::copy(h_.data(), h_.data() + n_, imf);
  return outcome;
}

}  // namespace gyrodrift::decomposition::internal
