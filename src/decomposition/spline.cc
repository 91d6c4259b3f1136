#include "decomposition/spline.h"

#include <algorithm>

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

// Forward elimination of rows [from, to) of two systems at once; diag becomes the inverse pivots.
// The pivot and right-hand side of the previous row stay in registers: the recurrence is one
// division chain per system, and the two chains overlap in the processor.
struct Chain {
  double* diag;
  double* rhs;
  const double* sub;
  const double* sup;
  double inv_prev, rhs_prev;
  explicit Chain(EnvelopeSpline::Rows rows)
      : diag(rows.diag), rhs(rows.rhs), sub(rows.sub), sup(rows.sup) {
    inv_prev = diag[0] = 1.0 / diag[0];
    rhs_prev = rhs[0];
  }
  inline void Step(size_t j) {
    const double w = sub[j] * inv_prev;
    inv_prev = 1.0 / (diag[j] - w * sup[j - 1]);
    rhs_prev = rhs[j] - w * rhs_prev;
    diag[j] = inv_prev;
    rhs[j] = rhs_prev;
  }
};

// Back substitution, s[j] = (rhs[j] - sup[j] s[j+1]) inv_diag[j], for rows m-1 down to 0.
struct Back {
  const double* inv_diag;
  const double* rhs;
  const double* sup;
  double* s;
  double next;
  Back(EnvelopeSpline::Rows rows, double* slope, size_t m)
      : inv_diag(rows.diag), rhs(rows.rhs), sup(rows.sup), s(slope) {
    next = s[m - 1] = rhs[m - 1] * inv_diag[m - 1];
  }
  inline void Step(size_t j) {
    next = (rhs[j] - sup[j] * next) * inv_diag[j];
    s[j] = next;
  }
};

}  // namespace

EnvelopeSpline::Rows EnvelopeSpline::rows() {
  return {diag_.data(), rhs_.data(), sub_.data(), sup_.data()};
}

void EnvelopeSpline::Coefficients() {
  // Cubic coefficients per piece (MATLAB pwch): v = ((c1 h + c2) h + slope) h + y.
  const size_t m = t_.size();
  const double* inv_dx = inv_dx_.data();
  const double* dd = dd_.data();
  const double* slope = slope_.data();
  double* c1 = c1_.data();
  double* c2 = c2_.data();
  for (size_t k = 0; k + 1 < m; ++k) {
    const double dzzdx = (dd[k] - slope[k]) * inv_dx[k];
    const double dzdxdx = (slope[k + 1] - dd[k]) * inv_dx[k];
    c1[k] = (dzdxdx - dzzdx) * inv_dx[k];
    c2[k] = 2 * dzzdx - dzdxdx;
  }
}

void FitPair(EnvelopeSpline& a, EnvelopeSpline& b) {
  a.Prepare();
  b.Prepare();
  const size_t ma = a.t_.size() >= 4 ? a.t_.size() : 0;
  const size_t mb = b.t_.size() >= 4 ? b.t_.size() : 0;
  if (ma && mb) {
    // Both systems in one loop: two independent division chains.
    Chain ca(a.rows()), cb(b.rows());
    const size_t common = std::min(ma, mb);
    size_t j = 1;
    for (; j < common; ++j) {
      ca.Step(j);
      cb.Step(j);
    }
    for (size_t k = j; k < ma; ++k) ca.Step(k);
    for (size_t k = j; k < mb; ++k) cb.Step(k);
    Back ba(a.rows(), a.slope_.data(), ma), bb(b.rows(), b.slope_.data(), mb);
    size_t ja = ma - 1, jb = mb - 1;
    while (ja > 0 && jb > 0) {
      ba.Step(--ja);
      bb.Step(--jb);
    }
    while (ja > 0) ba.Step(--ja);
    while (jb > 0) bb.Step(--jb);
  } else {
    for (EnvelopeSpline* s : {&a, &b}) {
      const size_t m = s->t_.size();
      if (m < 4) continue;
      Chain c(s->rows());
      for (size_t j = 1; j < m; ++j) c.Step(j);
      Back back(s->rows(), s->slope_.data(), m);
      for (size_t j = m - 1; j-- > 0;) back.Step(j);
    }
  }
  if (ma) a.Coefficients();
  if (mb) b.Coefficients();
}

SplineView EnvelopeSpline::view() const {
  return {t_.size(), t_.data(), y_.data(), dd_.data(), c1_.data(), c2_.data(), slope_.data()};
}

void EnvelopeSpline::Evaluate(Eigen::Index n, double* out) const { SimdEvaluate(view(), n, out); }

void EnvelopeSpline::EvaluateSift(Eigen::Index n, const double* lower, const double* h,
                                  double* next) const {
  SimdEvaluateSift(view(), n, lower, h, next);
}

}  // namespace gyrodrift::decomposition::internal
