#include "decomposition/spline.h"

#include <algorithm>

namespace gyrodrift::decomposition::internal {

EnvelopeSpline::EnvelopeSpline(Eigen::Index max_nodes, int phase) {
  const size_t size = static_cast<size_t>(max_nodes) + 1;
  t_.reserve(size);
  y_.reserve(size);
  // The seven per-node arrays share one allocation, each starting 320 bytes further round the
  // 4 KiB page than the previous one (and phase 1 another 160 bytes): equal arrays allocated
  // apart would all start at the same offset in the page, and the sweeps, which walk all of
  // them (of both splines) at once, would compete for the same cache sets.
  const size_t stride = (size + 511) / 512 * 512 + 40;
  const size_t offset = 20 * static_cast<size_t>(phase);
  storage_.assign(7 * stride + offset, 0.0);
  double* base = storage_.data() + offset;
  for (double** p : {&inv_dx_, &dd_, &slope_, &diag_, &rhs_, &c1_, &c2_}) {
    *p = base;
    base += stride;
  }
}

// Not-a-knot slopes from the tridiagonal system (MATLAB spline.m), row j:
//   sub[j] s[j-1] + diag[j] s[j] + sup[j] s[j+1] = rhs[j],
// interior rows sub = dx_j, diag = 2 (dx_j + dx_{j-1}), sup = dx_{j-1},
// rhs = 3 (dx_j dd_{j-1} + dx_{j-1} dd_j), and rows 0 and m-1 carrying the not-a-knot conditions.
// The rows are built inside the elimination sweep, which is bound by its division chain, so
// building them there costs no extra time and nothing but the inverse pivots and the eliminated
// right-hand side is stored; the cubic coefficients are likewise made in the back substitution.
// Every quantity is the same expression, in the same order, as the plain three-pass form.
namespace {

void DividedDifferences(const double* __restrict t, const double* __restrict y,
                        double* __restrict inv_dx, double* __restrict dd, size_t m) {
  for (size_t j = 0; j + 1 < m; ++j) {
    inv_dx[j] = 1.0 / (t[j + 1] - t[j]);
    dd[j] = (y[j + 1] - y[j]) * inv_dx[j];
  }
}

class Forward {
 public:
  Forward(const double* t, const double* y, double* inv_dx, double* dd, double* inv_diag,
          double* rhs, size_t m)
      : t_(t), dd_(dd), inv_diag_(inv_diag), rhs_(rhs), m_(m) {
    // The divided differences first, in a separate loop: its divisions are independent and
    // pipeline there, while inside the sweep they would queue with the pivot divisions.
    DividedDifferences(t, y, inv_dx, dd, m);
    const double dx0 = t[1] - t[0], dx1 = t[2] - t[1];
    const double x31 = t[2] - t[0];
    inv_prev_ = inv_diag_[0] = 1.0 / dx1;
    rhs_prev_ = rhs_[0] = ((dx0 + 2 * x31) * dx1 * dd_[0] + dx0 * dx0 * dd_[1]) / x31;
    sup_prev_ = x31;
    dd_prev_ = dd_[0];
    dd_cur_ = dd_[1];
  }
  // Interior row j, 1 <= j <= m-2 (in increasing order).
  inline void Row(size_t j) {
    const double* t = t_;
    const double dd_next = dd_[j + 1];
    const double dx_j = t[j + 1] - t[j];
    const double dx_prev = t[j] - t[j - 1];
    const double diag = 2 * (dx_j + dx_prev);
    const double rhs = 3 * (dx_j * dd_prev_ + dx_prev * dd_cur_);
    const double w = dx_j * inv_prev_;
    inv_prev_ = 1.0 / (diag - w * sup_prev_);
    rhs_prev_ = rhs - w * rhs_prev_;
    inv_diag_[j] = inv_prev_;
    rhs_[j] = rhs_prev_;
    sup_prev_ = dx_prev;
    dd_prev_ = dd_cur_;
    dd_cur_ = dd_next;
  }
  // Row m-1 (after every interior row).
  void Last() {
    const double* t = t_;
    const size_t m = m_;
    const double dxl = t[m - 1] - t[m - 2], dxl1 = t[m - 2] - t[m - 3];
    const double xn = t[m - 1] - t[m - 3];
    const double rhs = (dxl * dxl * dd_[m - 3] + (2 * xn + dxl) * dxl1 * dd_[m - 2]) / xn;
    const double w = xn * inv_prev_;
    inv_diag_[m - 1] = 1.0 / (dxl1 - w * sup_prev_);
    rhs_[m - 1] = rhs - w * rhs_prev_;
  }

 private:
  const double* t_;
  const double* dd_;
  double* inv_diag_;
  double* rhs_;
  size_t m_;
  double inv_prev_, rhs_prev_, sup_prev_, dd_prev_, dd_cur_;
};

// Back substitution s[j] = (rhs[j] - sup[j] s[j+1]) inv_diag[j] for j = m-2 .. 0, with the
// cubic coefficients of piece j (MATLAB pwch): v = ((c1 h + c2) h + slope) h + y.
class Backward {
 public:
  Backward(const double* t, const double* inv_dx, const double* dd, const double* inv_diag,
           const double* rhs, double* slope, double* c1, double* c2, size_t m)
      : t_(t),
        inv_dx_(inv_dx),
        dd_(dd),
        inv_diag_(inv_diag),
        rhs_(rhs),
        slope_(slope),
        c1_(c1),
        c2_(c2) {
    next_ = slope_[m - 1] = rhs_[m - 1] * inv_diag_[m - 1];
  }
  inline void Row(size_t j) {
    const double sup = j > 0 ? t_[j] - t_[j - 1] : t_[2] - t_[0];
    const double s = (rhs_[j] - sup * next_) * inv_diag_[j];
    slope_[j] = s;
    const double dzzdx = (dd_[j] - s) * inv_dx_[j];
    const double dzdxdx = (next_ - dd_[j]) * inv_dx_[j];
    c1_[j] = (dzdxdx - dzzdx) * inv_dx_[j];
    c2_[j] = 2 * dzzdx - dzdxdx;
    next_ = s;
  }

 private:
  const double* t_;
  const double* inv_dx_;
  const double* dd_;
  const double* inv_diag_;
  const double* rhs_;
  double* slope_;
  double* c1_;
  double* c2_;
  double next_;
};

}  // namespace

// Divided differences for the 2- and 3-node cases (a line, a parabola).
void EnvelopeSpline::Prepare() {
  DividedDifferences(t_.data(), y_.data(), inv_dx_, dd_, t_.size());
}

void FitPair(EnvelopeSpline& a, EnvelopeSpline& b) {
  const size_t ma = a.t_.size(), mb = b.t_.size();
  if (ma < 4) a.Prepare();
  if (mb < 4) b.Prepare();
  auto forward = [](EnvelopeSpline& s) {
    return Forward(s.t_.data(), s.y_.data(), s.inv_dx_, s.dd_, s.diag_, s.rhs_, s.t_.size());
  };
  auto backward = [](EnvelopeSpline& s) {
    return Backward(s.t_.data(), s.inv_dx_, s.dd_, s.diag_, s.rhs_, s.slope_, s.c1_, s.c2_,
                    s.t_.size());
  };
  if (ma >= 4 && mb >= 4) {
    // Both systems in one loop: two independent division chains overlap in the processor.
    Forward fa = forward(a), fb = forward(b);
    const size_t common = std::min(ma, mb) - 1;
    size_t j = 1;
    for (; j < common; ++j) {
      fa.Row(j);
      fb.Row(j);
    }
    for (size_t k = j; k + 1 < ma; ++k) fa.Row(k);
    for (size_t k = j; k + 1 < mb; ++k) fb.Row(k);
    fa.Last();
    fb.Last();
    Backward ba = backward(a), bb = backward(b);
    size_t ja = ma - 1, jb = mb - 1;
    while (ja > 0 && jb > 0) {
      ba.Row(--ja);
      bb.Row(--jb);
    }
    while (ja > 0) ba.Row(--ja);
    while (jb > 0) bb.Row(--jb);
    return;
  }
  for (EnvelopeSpline* s : {&a, &b}) {
    const size_t m = s->t_.size();
    if (m < 4) continue;
    Forward f = forward(*s);
    for (size_t j = 1; j + 1 < m; ++j) f.Row(j);
    f.Last();
    Backward back = backward(*s);
    for (size_t j = m - 1; j-- > 0;) back.Row(j);
  }
}

SplineView EnvelopeSpline::view() const {
  return {t_.size(), t_.data(), y_.data(), dd_, c1_, c2_, slope_};
}

void EnvelopeSpline::Evaluate(Eigen::Index n, double* out) const { SimdEvaluate(view(), n, out); }

void EnvelopeSpline::EvaluateSift(Eigen::Index n, const double* lower, const double* h,
                                  double* next) const {
  SimdEvaluateSift(view(), n, lower, h, next);
}

}  // namespace gyrodrift::decomposition::internal
