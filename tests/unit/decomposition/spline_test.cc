// The envelope spline's solve: one plain three-pass not-a-knot solve (build the tridiagonal
// rows, eliminate, substitute back) written out here gives the same bits as FitPair, whether
// FitPair sweeps a system in one piece or in warmed-up pieces, and whether those pieces start
// from the right state or have to be recomputed (a warm-up of 1 row almost never lands on it).
#include "decomposition/spline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "gyrodrift/common/random.h"

namespace gyrodrift::decomposition::internal {
namespace {

// Integer node times from -2 past n + 1 with gaps drawn from `gaps`.
std::vector<double> NodeTimes(Eigen::Index n, const std::vector<int>& gaps, Rng& rng) {
  std::vector<double> t{-2.0};
  while (t.back() < static_cast<double>(n) + 1) {
    const auto pick = static_cast<size_t>(rng.Uniform() * static_cast<double>(gaps.size()));
    t.push_back(t.back() + gaps[std::min(pick, gaps.size() - 1)]);
  }
  return t;
}

// The textbook form, every quantity the same expression as in spline.cc, evaluated at 1..n as
// the vector kernels do (v = ((c1 h + c2) h + slope) h + y).
std::vector<double> PlainSpline(const std::vector<double>& t, const std::vector<double>& y,
                                Eigen::Index n) {
  const size_t m = t.size();
  std::vector<double> inv_dx(m - 1), dd(m - 1);
  for (size_t j = 0; j + 1 < m; ++j) {
    inv_dx[j] = 1.0 / (t[j + 1] - t[j]);
    dd[j] = (y[j + 1] - y[j]) * inv_dx[j];
  }
  std::vector<double> sub(m), diag(m), sup(m), rhs(m);
  const double dx0 = t[1] - t[0], dx1 = t[2] - t[1], x31 = t[2] - t[0];
  diag[0] = dx1;
  sup[0] = x31;
  rhs[0] = ((dx0 + 2 * x31) * dx1 * dd[0] + dx0 * dx0 * dd[1]) / x31;
  for (size_t j = 1; j + 1 < m; ++j) {
    const double dx_j = t[j + 1] - t[j], dx_prev = t[j] - t[j - 1];
    sub[j] = dx_j;
    diag[j] = 2 * (dx_j + dx_prev);
    sup[j] = dx_prev;
    rhs[j] = 3 * (dx_j * dd[j - 1] + dx_prev * dd[j]);
  }
  const double dxl = t[m - 1] - t[m - 2], dxl1 = t[m - 2] - t[m - 3], xn = t[m - 1] - t[m - 3];
  sub[m - 1] = xn;
  diag[m - 1] = dxl1;
  rhs[m - 1] = (dxl * dxl * dd[m - 3] + (2 * xn + dxl) * dxl1 * dd[m - 2]) / xn;
  std::vector<double> inv(m), r(m), s(m);
  inv[0] = 1.0 / diag[0];
  r[0] = rhs[0];
  for (size_t j = 1; j < m; ++j) {
    const double w = sub[j] * inv[j - 1];
    inv[j] = 1.0 / (diag[j] - w * sup[j - 1]);
    r[j] = rhs[j] - w * r[j - 1];
  }
  s[m - 1] = r[m - 1] * inv[m - 1];
  for (size_t j = m - 1; j-- > 0;) s[j] = (r[j] - sup[j] * s[j + 1]) * inv[j];
  std::vector<double> out(static_cast<size_t>(n));
  size_t j = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double at = static_cast<double>(i + 1);
    while (j + 2 < m && at >= t[j + 1]) ++j;
    const double dzzdx = (dd[j] - s[j]) * inv_dx[j];
    const double dzdxdx = (s[j + 1] - dd[j]) * inv_dx[j];
    const double c1 = (dzdxdx - dzzdx) * inv_dx[j];
    const double c2 = 2 * dzzdx - dzdxdx;
    const double h = at - t[j];
    out[static_cast<size_t>(i)] = ((h * c1 + c2) * h + s[j]) * h + y[j];
  }
  return out;
}

struct Case {
  Eigen::Index n_lower, n_upper;  // samples covered; node counts follow from the gaps
  std::vector<int> gaps;
};

TEST(EnvelopeSpline, EveryWayOfSweepingGivesThePlainSolvesBits) {
  Rng rng(21, 0);
  const std::vector<Case> cases = {
      {5, 5, {1, 2}},                      // 4-6 nodes: the smallest systems
      {1500, 1500, {1, 2, 3, 4, 5}},       // both long enough for pieces (>= 384 nodes)
      {1500, 800, {1, 2, 3}},              // one in pieces, one plain
      {900, 1100, {2, 3}},                 // around the piece threshold
      {30000, 28000, {1, 2, 3, 4, 5, 6}},  // white-noise first-mode sizes
      {40000, 40000, {1, 1, 1, 500}},      // uneven spacing: slower forgetting
      {20000, 20000, {1, 1000}},           // extreme ratios between neighbouring gaps
  };
  const size_t plain_only = std::numeric_limits<size_t>::max() / 16;
  for (const Case& c : cases) {
    const Eigen::Index n = std::min(c.n_lower, c.n_upper);
    const std::vector<double> tl = NodeTimes(c.n_lower, c.gaps, rng);
    const std::vector<double> tu = NodeTimes(c.n_upper, c.gaps, rng);
    std::vector<double> yl(tl.size()), yu(tu.size());
    for (double& v : yl) v = rng.Normal();
    for (double& v : yu) v = 1e3 * rng.Normal();
    const std::vector<double> expected_lower = PlainSpline(tl, yl, n);
    const std::vector<double> expected_upper = PlainSpline(tu, yu, n);
    for (size_t warm_up : {kSplineWarmUp, size_t{1}, size_t{3}, plain_only}) {
      EnvelopeSpline lower(static_cast<Eigen::Index>(tl.size() + 4));
      EnvelopeSpline upper(static_cast<Eigen::Index>(tu.size() + 4), 1);
      lower.t() = tl;
      lower.y() = yl;
      upper.t() = tu;
      upper.y() = yu;
      FitPair(lower, upper, warm_up);
      std::vector<double> lo(static_cast<size_t>(n + EnvelopeSpline::kPadding));
      std::vector<double> hi(lo.size());
      lower.Evaluate(n, lo.data());
      upper.Evaluate(n, hi.data());
      const size_t bytes = static_cast<size_t>(n) * sizeof(double);
      EXPECT_EQ(std::memcmp(lo.data(), expected_lower.data(), bytes), 0)
          << tl.size() << " lower nodes, warm-up " << warm_up;
      EXPECT_EQ(std::memcmp(hi.data(), expected_upper.data(), bytes), 0)
          << tu.size() << " upper nodes, warm-up " << warm_up;
    }
  }
}

}  // namespace
}  // namespace gyrodrift::decomposition::internal
