#include "decomposition/sifting.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
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

// emd.m's zero crossings: strict sign changes plus one per run of exact zeros.
int CountZeroCrossings(const double* x, Eigen::Index n) {
  std::int64_t changes = 0, zeros = 0;
  Eigen::Index i = 0;
#if defined(__SSE2__)
  // Each true comparison lane is all ones (-1 as an integer): subtracting counts it.
  __m128i change_acc = _mm_setzero_si128(), zero_acc = _mm_setzero_si128();
  const __m128d zero = _mm_setzero_pd();
  for (; i + 2 < n; i += 2) {
    const __m128d a = _mm_loadu_pd(x + i);
    const __m128d b = _mm_loadu_pd(x + i + 1);
    change_acc = _mm_sub_epi64(change_acc, _mm_castpd_si128(_mm_cmplt_pd(_mm_mul_pd(a, b), zero)));
    zero_acc = _mm_sub_epi64(zero_acc, _mm_castpd_si128(_mm_cmpeq_pd(a, zero)));
  }
  alignas(16) std::int64_t lanes[2];
  _mm_store_si128(reinterpret_cast<__m128i*>(lanes), change_acc);
  changes = lanes[0] + lanes[1];
  _mm_store_si128(reinterpret_cast<__m128i*>(lanes), zero_acc);
  zeros = lanes[0] + lanes[1];
#endif
  for (; i + 1 < n; ++i) {
    changes += x[i] * x[i + 1] < 0.0;
    zeros += x[i] == 0.0;
  }
  if (n > 0) zeros += x[n - 1] == 0.0;
  return static_cast<int>(zeros ? changes + ZeroRuns(x, n) : changes);
}

// Index lists are short (<= nbsym + 1); fliplr(ind(from:to)) in 0-based half-open form.
struct NodeList {
  int v[kNbSym + 2] = {};
  int size = 0;
  void Clear() { size = 0; }
  void Push(int i) { v[size++] = i; }
  void PushReversed(const int* ind, int from, int to) {
    for (int k = to - 1; k >= from; --k) Push(ind[k]);
  }
};

// The extrema of a sift (FindExtrema): 0-based indices in increasing order.
struct ExtremaIndices {
  const int* imin;
  int nmin;
  const int* imax;
  int nmax;
};

// The extrema mirrored at one end of the signal, and the sample they are mirrored about.
struct EndNodes {
  NodeList min, max;
  int sym;
};

// Times are t = index + 1; a node mirrored about sample s sits at 2 t(s) - t(node).
double Mirrored(int sym, int node) { return 2.0 * (sym + 1) - (node + 1); }

// emd.m's nbsym extrema at the start, mirrored about the first extremum or the first sample.
// e has at least one extremum of each kind.
EndNodes LeftEnd(const double* h, const ExtremaIndices& e) {
  const int *imin = e.imin, *imax = e.imax;
  const int nmin = e.nmin, nmax = e.nmax;
  EndNodes l;
  if (imax[0] < imin[0]) {
    if (h[0] > h[imin[0]]) {
      l.max.PushReversed(imax, 1, std::min(nmax, kNbSym + 1));
      l.min.PushReversed(imin, 0, std::min(nmin, kNbSym));
      l.sym = imax[0];
    } else {
      l.max.PushReversed(imax, 0, std::min(nmax, kNbSym));
      l.min.PushReversed(imin, 0, std::min(nmin, kNbSym - 1));
      l.min.Push(0);
      l.sym = 0;
    }
  } else {
    if (h[0] < h[imax[0]]) {
      l.max.PushReversed(imax, 0, std::min(nmax, kNbSym));
      l.min.PushReversed(imin, 1, std::min(nmin, kNbSym + 1));
      l.sym = imin[0];
    } else {
      l.max.PushReversed(imax, 0, std::min(nmax, kNbSym - 1));
      l.max.Push(0);
      l.min.PushReversed(imin, 0, std::min(nmin, kNbSym));
      l.sym = 0;
    }
  }
  return l;
}

// The same at the end, sample `last`.
EndNodes RightEnd(const double* h, const ExtremaIndices& e, int last) {
  const int *imin = e.imin, *imax = e.imax;
  const int nmin = e.nmin, nmax = e.nmax;
  EndNodes r;
  if (imax[nmax - 1] < imin[nmin - 1]) {
    if (h[last] < h[imax[nmax - 1]]) {
      r.max.PushReversed(imax, std::max(nmax - kNbSym, 0), nmax);
      r.min.PushReversed(imin, std::max(nmin - kNbSym - 1, 0), nmin - 1);
      r.sym = imin[nmin - 1];
    } else {
      r.max.Push(last);
      r.max.PushReversed(imax, std::max(nmax - kNbSym + 1, 0), nmax);
      r.min.PushReversed(imin, std::max(nmin - kNbSym, 0), nmin);
      r.sym = last;
    }
  } else {
    if (h[last] > h[imin[nmin - 1]]) {
      r.max.PushReversed(imax, std::max(nmax - kNbSym - 1, 0), nmax - 1);
      r.min.PushReversed(imin, std::max(nmin - kNbSym, 0), nmin);
      r.sym = imax[nmax - 1];
    } else {
      r.max.PushReversed(imax, std::max(nmax - kNbSym, 0), nmax);
      r.min.Push(last);
      r.min.PushReversed(imin, std::max(nmin - kNbSym + 1, 0), nmin);
      r.sym = last;
    }
  }
  return r;
}

// emd.m: "in case symmetrized parts do not extend enough": where the mirrored nodes do not reach
// back to the first sample, mirror about the first sample instead. Indexing an empty list there is
// an error in MATLAB (caught as "stop sifting"), hence the returns of false.
bool CoverLeft(const ExtremaIndices& e, EndNodes& l) {
  constexpr double kTFirst = 1.0;
  if (l.min.size == 0) return false;
  bool short_of_end = Mirrored(l.sym, l.min.v[0]) > kTFirst;
  if (!short_of_end) {
    if (l.max.size == 0) return false;
    short_of_end = Mirrored(l.sym, l.max.v[0]) > kTFirst;
  }
  if (!short_of_end) return true;
  if (l.sym == e.imax[0]) {
    l.max.Clear();
    l.max.PushReversed(e.imax, 0, std::min(e.nmax, kNbSym));
  } else {
    l.min.Clear();
    l.min.PushReversed(e.imin, 0, std::min(e.nmin, kNbSym));
  }
  if (l.sym == 0) return false;
  l.sym = 0;
  return true;
}

// The same at the end, sample `last` (time last + 1).
bool CoverRight(const ExtremaIndices& e, int last, EndNodes& r) {
  const double t_last = static_cast<double>(last + 1);
  if (r.min.size == 0) return false;
  bool short_of_end = Mirrored(r.sym, r.min.v[r.min.size - 1]) < t_last;
  if (!short_of_end) {
    if (r.max.size == 0) return false;
    short_of_end = Mirrored(r.sym, r.max.v[r.max.size - 1]) < t_last;
  }
  if (!short_of_end) return true;
  if (r.sym == e.imax[e.nmax - 1]) {
    r.max.Clear();
    r.max.PushReversed(e.imax, std::max(e.nmax - kNbSym, 0), e.nmax);
  } else {
    r.min.Clear();
    r.min.PushReversed(e.imin, std::max(e.nmin - kNbSym, 0), e.nmin);
  }
  if (r.sym == last) return false;
  r.sym = last;
  return true;
}

// One envelope's nodes (t, z): the left mirrored nodes, the interior extrema, the right mirrored
// nodes. False where interp1 would refuse them (fewer than 2, or not increasing).
bool AssembleNodes(const double* h, const NodeList& left, int lsym, const int* interior, int count,
                   const NodeList& right, int rsym, std::vector<double>& t,
                   std::vector<double>& z) {
  const size_t total = static_cast<size_t>(left.size + count + right.size);
  assert(total <= t.capacity() && total <= z.capacity());  // the sift loop allocates nothing
  t.resize(total);  // within the reserved capacity: no allocation
  z.resize(total);
  size_t k = 0;
  for (int j = 0; j < left.size; ++j, ++k) {
    t[k] = Mirrored(lsym, left.v[j]);
    z[k] = h[left.v[j]];
  }
  double* tk = t.data() + k;
  double* zk = z.data() + k;
  for (int j = 0; j < count; ++j) {
    tk[j] = interior[j] + 1.0;
    zk[j] = h[interior[j]];
  }
  k += static_cast<size_t>(count);
  for (int j = 0; j < right.size; ++j, ++k) {
    t[k] = Mirrored(rsym, right.v[j]);
    z[k] = h[right.v[j]];
  }
  if (total < 2) return false;
  // interp1 needs distinct increasing nodes; the interior ones are, by construction.
  const size_t edge = static_cast<size_t>(left.size);
  for (size_t j = 1; j <= edge && j < total; ++j) {
    if (!(t[j] > t[j - 1])) return false;
  }
  for (size_t j = total - static_cast<size_t>(right.size); j < total; ++j) {
    if (j > 0 && !(t[j] > t[j - 1])) return false;
  }
  return true;
}

}  // namespace

ExtremaCounts CountExtrema(const double* x, Eigen::Index n) {
  ExtremaCounts c{0, 0, CountZeroCrossings(x, n)};
  bool flat = false;
  if (n >= 2) flat = x[1] - x[0] == 0.0;
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    const double d0 = x[i] - x[i - 1];
    const double d1 = x[i + 1] - x[i];
    const bool is_ext = d0 * d1 < 0.0;
    c.minima += is_ext & (d0 < 0.0);
    c.maxima += is_ext & (d0 > 0.0);
    flat |= d1 == 0.0;
  }
  if (flat) {
    PlateauExtrema(x, n, [&](Eigen::Index, bool is_max) { ++(is_max ? c.maxima : c.minima); });
  }
  return c;
}

Sifter::Sifter(Eigen::Index n, const SiftingOptions& options)
    : n_(n),
      options_(options),
      max_sifts_(options.EffectiveMaxSifts()),
      lower_(n + 2 * kNbSym + 4, 0),
      upper_(n + 2 * kNbSym + 4, 1) {
  const size_t size = static_cast<size_t>(n);
  indmin_.resize(size + 2);
  indmax_.resize(size + 2);
  // Padded (zeros) for the fused sift's fixed-width blocks. Only the padding is zeroed: the
  // first n values are written before they are read, and env_max_, which the fused sift never
  // stores, then costs no memory.
  for (Eigen::VectorXd* v : {&h_, &next_, &env_min_, &env_max_}) {
    v->resize(n + EnvelopeSpline::kPadding);
    v->tail(EnvelopeSpline::kPadding).setZero();
  }
}

void Sifter::ReleaseNodeBuffers() {
  lower_.ReleaseStorage();
  upper_.ReleaseStorage();
  ReleasePages(indmin_.data(), indmin_.size() * sizeof(int));
  ReleasePages(indmax_.data(), indmax_.size() * sizeof(int));
}

void Sifter::Envelopes() {
  FitPair(lower_, upper_);
  lower_.Evaluate(n_, env_min_.data());
  upper_.Evaluate(n_, env_max_.data());
}

ExtremaCounts Sifter::FindExtrema(const double* h, bool count_zero_crossings) {
  ExtremaCounts c;
  ExtremaScan scan;
  scan.indmin = indmin_.data();
  scan.indmax = indmax_.data();
  const bool flat = SimdFindStrictExtrema(h, n_, count_zero_crossings, &scan);
  c.minima = scan.nmin;
  c.maxima = scan.nmax;
  if (count_zero_crossings) {
    // The zero-crossing count of CountZeroCrossings, from the same pass.
    c.zero_crossings =
        static_cast<int>(scan.has_zero ? scan.sign_changes + ZeroRuns(h, n_) : scan.sign_changes);
  }
  if (flat) {
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
          indmax_[cap - static_cast<size_t>(extra_max) + static_cast<size_t>(px++)] =
              static_cast<int>(i);
        } else {
          indmin_[cap - static_cast<size_t>(extra_min) + static_cast<size_t>(pm++)] =
              static_cast<int>(i);
        }
      });
      auto merge_back = [cap](UninitialisedVector<int>& ind, int strict, int extra) {
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
  nmin_ = c.minima;
  nmax_ = c.maxima;
  return c;
}

bool Sifter::BoundaryConditions(const double* h) {
  // Counts are the current FindExtrema result, stored by the caller in nmin_/nmax_.
  const ExtremaIndices e{indmin_.data(), nmin_, indmax_.data(), nmax_};
  if (e.nmin + e.nmax < 3 || e.nmin == 0 || e.nmax == 0) return false;
  const int last = static_cast<int>(n_) - 1;
  EndNodes left = LeftEnd(h, e), right = RightEnd(h, e, last);
  if (!CoverLeft(e, left) || !CoverRight(e, last, right)) return false;
  return AssembleNodes(h, left.min, left.sym, e.imin, e.nmin, right.min, right.sym, lower_.t(),
                       lower_.y()) &&
         AssembleNodes(h, left.max, left.sym, e.imax, e.nmax, right.max, right.sym, upper_.t(),
                       upper_.y());
}

bool Sifter::EnvelopeNodes(const double* x, std::vector<double>* tmin, std::vector<double>* zmin,
                           std::vector<double>* tmax, std::vector<double>* zmax) {
  FindExtrema(x, false);
  if (!BoundaryConditions(x)) return false;
  *tmin = lower_.t();
  *zmin = lower_.y();
  *tmax = upper_.t();
  *zmax = upper_.y();
  return true;
}

bool Sifter::MeanAndAmplitude(const double* x, double* mean, double* amplitude) {
  FindExtrema(x, false);
  if (!BoundaryConditions(x)) return false;
  Envelopes();
  for (Eigen::Index i = 0; i < n_; ++i) {
    mean[i] = (env_min_[i] + env_max_[i]) / 2;
    amplitude[i] = std::abs(env_max_[i] - env_min_[i]) / 2;
  }
  return true;
}

SiftOutcome Sifter::ExtractImf(const double* x, double* imf) {
  SiftOutcome outcome;
  std::copy(x, x + n_, h_.data());
  const StopRule rule = options_.stop_rule;
  const bool every_sift_zc = rule == StopRule::kSNumber;
  ExtremaCounts counts = FindExtrema(h_.data(), every_sift_zc);
  if (counts.extrema() < 3) {
    outcome.extracted = false;
    return outcome;
  }
  const double n_double = static_cast<double>(n_);
  int stable = 0;
  ExtremaCounts previous = counts;
  for (;;) {
    if (rule == StopRule::kSNumber && outcome.sifts > 0) {
      // Huang et al. (2003) as libeemd implements it: the counts of maxima, minima and zero
      // crossings change by at most one in total from one sift to the next, S times in a row,
      // and extrema and zero crossings then differ by at most one.
      const int change = std::abs(counts.maxima - previous.maxima) +
                         std::abs(counts.minima - previous.minima) +
                         std::abs(counts.zero_crossings - previous.zero_crossings);
      stable = change <= 1 ? stable + 1 : 0;
      previous = counts;
      if (stable >= options_.s_number && std::abs(counts.extrema() - counts.zero_crossings) <= 1) {
        break;
      }
    }
    if (rule == StopRule::kFixed && outcome.sifts >= options_.fixed_sifts) break;

    if (counts.extrema() < 3 || !BoundaryConditions(h_.data())) break;  // emd.m's catch: stop
    if (rule == StopRule::kSNumber || rule == StopRule::kFixed) {
      FitPair(lower_, upper_);
      lower_.Evaluate(n_, env_min_.data());
    } else {
      Envelopes();
    }

    const double* h = h_.data();
    const double* lo = env_min_.data();
    const double* hi = env_max_.data();
    double* next = next_.data();
    bool stop = false;
    if (rule == StopRule::kRilling) {
      const double t1 = options_.rilling_threshold1, t2 = options_.rilling_threshold2;
      const RillingCounts c = SimdRillingSift(lo, hi, h, next, n_, t1, t2);
      const bool keep_sifting =
          static_cast<double>(c.above1) / n_double > options_.rilling_tolerance || c.above2;
      stop = !keep_sifting && std::abs(CountZeroCrossings(h, n_) - counts.extrema()) <= 1;
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
      upper_.EvaluateSift(n_, lo, h, next);  // the upper envelope is never stored
    }
    if (outcome.sifts >= max_sifts_) {
      outcome.cap_hit = true;
      break;
    }
    std::swap(h_, next_);
    ++outcome.sifts;
    if (stop) break;  // Cauchy SD: the sift that met the threshold is kept
    counts = FindExtrema(h_.data(), every_sift_zc);
  }
  std::copy(h_.data(), h_.data() + n_, imf);
  return outcome;
}

}  // namespace gyrodrift::decomposition::internal
