#include "decomposition/spline.h"

#include <algorithm>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gyrodrift::decomposition::internal {

EnvelopeSpline::EnvelopeSpline(Eigen::Index max_nodes) {
  const size_t size = static_cast<size_t>(max_nodes) + 1;
  t_.reserve(size);
  y_.reserve(size);
  for (auto* v : {&inv_dx_, &dd_, &slope_, &diag_, &rhs_, &sub_, &sup_, &c1_, &c2_}) v->resize(size);
}

// Differences and the rows of the tridiagonal system for the slopes (vectorisable loops).
// Row j: sub[j] s[j-1] + diag[j] s[j] + sup[j] s[j+1] = rhs[j]; rows 0 and m-1 carry the
// not-a-knot conditions.
void EnvelopeSpline::Prepare() {
  const size_t m = t_.size();
  const double* t = t_.data();
  const double* y = y_.data();
  double* inv_dx = inv_dx_.data();
  double* dd = dd_.data();
  for (size_t j = 0; j + 1 < m; ++j) {
    inv_dx[j] = 1.0 / (t[j + 1] - t[j]);
    dd[j] = (y[j + 1] - y[j]) * inv_dx[j];
  }
  if (m < 4) return;
  double* diag = diag_.data();
  double* rhs = rhs_.data();
  double* sub = sub_.data();
  double* sup = sup_.data();
  for (size_t j = 1; j + 1 < m; ++j) {
    const double dx_j = t[j + 1] - t[j];
    const double dx_prev = t[j] - t[j - 1];
    sub[j] = dx_j;
    diag[j] = 2 * (dx_j + dx_prev);
    sup[j] = dx_prev;
    rhs[j] = 3 * (dx_j * dd[j - 1] + dx_prev * dd[j]);
  }
  const double dx0 = t[1] - t[0], dx1 = t[2] - t[1];
  const double x31 = t[2] - t[0];
  diag[0] = dx1;
  sup[0] = x31;
  rhs[0] = ((dx0 + 2 * x31) * dx1 * dd[0] + dx0 * dx0 * dd[1]) / x31;
  const double dxl = t[m - 1] - t[m - 2], dxl1 = t[m - 2] - t[m - 3];
  const double xn = t[m - 1] - t[m - 3];
  sub[m - 1] = xn;
  diag[m - 1] = dxl1;
  rhs[m - 1] = (dxl * dxl * dd[m - 3] + (2 * xn + dxl) * dxl1 * dd[m - 2]) / xn;
}

namespace {

// Forward elimination of rows [1, m) of one system; diag becomes the inverse pivots.
inline void EliminateRow(double* diag, double* rhs, const double* sub, const double* sup, size_t j) {
  const double w = sub[j] * diag[j - 1];
  diag[j] = 1.0 / (diag[j] - w * sup[j - 1]);
  rhs[j] -= w * rhs[j - 1];
}

void BackSubstitute(size_t m, const double* inv_diag, const double* rhs, const double* sup,
                    double* s) {
  s[m - 1] = rhs[m - 1] * inv_diag[m - 1];
  for (size_t j = m - 1; j-- > 0;) s[j] = (rhs[j] - sup[j] * s[j + 1]) * inv_diag[j];
}

}  // namespace

void FitPair(EnvelopeSpline& a, EnvelopeSpline& b) {
  a.Prepare();
  b.Prepare();
  const size_t ma = a.t_.size() >= 4 ? a.t_.size() : 0;
  const size_t mb = b.t_.size() >= 4 ? b.t_.size() : 0;
  if (ma) a.diag_[0] = 1.0 / a.diag_[0];
  if (mb) b.diag_[0] = 1.0 / b.diag_[0];
  // Two independent division chains in one loop: the processor overlaps them.
  const size_t common = std::min(ma, mb);
  size_t j = 1;
  for (; j < common; ++j) {
    EliminateRow(a.diag_.data(), a.rhs_.data(), a.sub_.data(), a.sup_.data(), j);
    EliminateRow(b.diag_.data(), b.rhs_.data(), b.sub_.data(), b.sup_.data(), j);
  }
  for (size_t k = j; k < ma; ++k) {
    EliminateRow(a.diag_.data(), a.rhs_.data(), a.sub_.data(), a.sup_.data(), k);
  }
  for (size_t k = j; k < mb; ++k) {
    EliminateRow(b.diag_.data(), b.rhs_.data(), b.sub_.data(), b.sup_.data(), k);
  }
  for (EnvelopeSpline* s : {&a, &b}) {
    const size_t m = s->t_.size();
    if (m < 4) continue;
    BackSubstitute(m, s->diag_.data(), s->rhs_.data(), s->sup_.data(), s->slope_.data());
    // Cubic coefficients per piece (MATLAB pwch): v = ((c1 h + c2) h + slope) h + y.
    const double* inv_dx = s->inv_dx_.data();
    const double* dd = s->dd_.data();
    const double* slope = s->slope_.data();
    double* c1 = s->c1_.data();
    double* c2 = s->c2_.data();
    for (size_t k = 0; k + 1 < m; ++k) {
      const double dzzdx = (dd[k] - slope[k]) * inv_dx[k];
      const double dzdxdx = (slope[k + 1] - dd[k]) * inv_dx[k];
      c1[k] = (dzdxdx - dzzdx) * inv_dx[k];
      c2[k] = 2 * dzzdx - dzdxdx;
    }
  }
}

void EnvelopeSpline::Evaluate(Eigen::Index n, double* out) const {
  const size_t m = t_.size();
  const double* t = t_.data();
  const double* y = y_.data();
  if (m == 2) {
    const double slope = dd_[0];
    for (Eigen::Index i = 0; i < n; ++i) out[i] = slope * (static_cast<double>(i + 1) - t[0]) + y[0];
    return;
  }
  if (m == 3) {
    const double c2 = (dd_[1] - dd_[0]) / (t[2] - t[0]);
    const double c1 = dd_[0] - c2 * (t[1] - t[0]);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double h = static_cast<double>(i + 1) - t[0];
      out[i] = (c2 * h + c1) * h + y[0];
    }
    return;
  }
  const double* c1 = c1_.data();
  const double* c2 = c2_.data();
  const double* s = slope_.data();
  Eigen::Index i = 0;
  for (size_t j = 0; j + 1 < m && i < n; ++j) {
    // Samples with t in [t_j, t_{j+1}) belong to piece j (the last piece takes the rest).
    const Eigen::Index end =
        j + 2 < m ? std::clamp(static_cast<Eigen::Index>(t[j + 1]) - 1, i, n) : n;
    const double a = c1[j], b = c2[j], c = s[j], d = y[j];
    const double base = static_cast<double>(i + 1) - t[j];
    if (end - i <= 4) {
      // Dense nodes: a fixed-width block (the buffer is padded) avoids a mispredicted loop exit;
      // values past `end` are overwritten by the next piece.
#if defined(__SSE2__)
      const __m128d va = _mm_set1_pd(a), vb = _mm_set1_pd(b), vc = _mm_set1_pd(c), vd = _mm_set1_pd(d);
      const __m128d h0 = _mm_set_pd(base + 1.0, base);
      const __m128d h1 = _mm_add_pd(h0, _mm_set1_pd(2.0));
      __m128d v0 = _mm_add_pd(_mm_mul_pd(h0, va), vb);
      __m128d v1 = _mm_add_pd(_mm_mul_pd(h1, va), vb);
      v0 = _mm_add_pd(_mm_mul_pd(v0, h0), vc);
      v1 = _mm_add_pd(_mm_mul_pd(v1, h1), vc);
      _mm_storeu_pd(out + i, _mm_add_pd(_mm_mul_pd(v0, h0), vd));
      _mm_storeu_pd(out + i + 2, _mm_add_pd(_mm_mul_pd(v1, h1), vd));
#else
      for (int k = 0; k < 4; ++k) {
        const double h = base + k;
        out[i + k] = ((h * a + b) * h + c) * h + d;
      }
#endif
    } else {
      const Eigen::Index length = end - i;
      Eigen::Index k = 0;
#if defined(__SSE2__)
      // Two samples per step; the same operations in the same order as the scalar Horner form,
      // so the values are the same bits.
      const __m128d va = _mm_set1_pd(a), vb = _mm_set1_pd(b), vc = _mm_set1_pd(c), vd = _mm_set1_pd(d);
      const __m128d two = _mm_set1_pd(2.0);
      __m128d h = _mm_set_pd(base + 1.0, base);
      for (; k + 2 <= length; k += 2) {
        __m128d v = _mm_add_pd(_mm_mul_pd(h, va), vb);
        v = _mm_add_pd(_mm_mul_pd(v, h), vc);
        v = _mm_add_pd(_mm_mul_pd(v, h), vd);
        _mm_storeu_pd(out + i + k, v);
        h = _mm_add_pd(h, two);
      }
#endif
      for (; k < length; ++k) {
        const double h = base + static_cast<double>(k);
        out[i + k] = ((h * a + b) * h + c) * h + d;
      }
    }
    i = end;
  }
}

}  // namespace gyrodrift::decomposition::internal
