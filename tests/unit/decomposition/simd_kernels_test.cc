// The vector kernels of one sift: the fused sift update equals the plain evaluation followed by
// the update, the AVX2 and SSE2 builds give the same bits, the fused zero-crossing count equals
// the reference count (including zeros, plateaus and products that underflow), and the vector
// Rilling sift equals its scalar form.
#include "decomposition/simd_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "decomposition/sifting.h"
#include "decomposition/spline.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::decomposition::internal {
namespace {

// Restores automatic path selection when a test ends.
struct PathGuard {
  ~PathGuard() { SetSimdPath(SimdPath::kAuto); }
};

bool SameBits(const double* a, const double* b, Eigen::Index n) {
  return std::memcmp(a, b, static_cast<size_t>(n) * sizeof(double)) == 0;
}

// Node sets with integer times covering 1..n: dense (gaps of 1-3 samples), sparse (long
// pieces) and the 2- and 3-node special cases, with mirrored nodes outside [1, n].
std::vector<double> NodeTimes(Eigen::Index n, int max_gap, Rng& rng) {
  std::vector<double> t{-2.0};
  while (t.back() < static_cast<double>(n) + 1) {
    t.push_back(t.back() + 1.0 + std::floor(rng.Uniform() * max_gap));
  }
  return t;
}

void FillValues(EnvelopeSpline& s, const std::vector<double>& t, Rng& rng) {
  s.t() = t;
  s.y().resize(t.size());
  for (double& v : s.y()) v = rng.Normal();
}

TEST(SplineSimd, FusedSiftEqualsEvaluateThenUpdate) {
  PathGuard guard;
  Rng rng(11, 0);
  for (int path = 0; path < 2; ++path) {
    SetSimdPath(path == 0 ? SimdPath::kBaseline : SimdPath::kAvx2);
    for (Eigen::Index n : {5, 17, 1000, 4099}) {
      for (int max_gap : {3, 9, 200, 100000}) {
        EnvelopeSpline lower(n + 16), upper(n + 16);
        FillValues(lower, NodeTimes(n, max_gap, rng), rng);
        FillValues(upper, NodeTimes(n, max_gap, rng), rng);
        FitPair(lower, upper);
        const Eigen::Index size = n + EnvelopeSpline::kPadding;
        Eigen::VectorXd h(size), lo(size), hi(size), expected(n), next(size);
        for (Eigen::Index i = 0; i < size; ++i) h[i] = rng.Normal();
        lower.Evaluate(n, lo.data());
        upper.Evaluate(n, hi.data());
        for (Eigen::Index i = 0; i < n; ++i) expected[i] = h[i] - (lo[i] + hi[i]) / 2;
        upper.EvaluateSift(n, lo.data(), h.data(), next.data());
        EXPECT_TRUE(SameBits(next.data(), expected.data(), n))
            << "path " << path << " n " << n << " gap " << max_gap;
      }
    }
  }
}

TEST(SplineSimd, Avx2AndBaselineGiveTheSameBits) {
  if (!SimdAvx2Available()) GTEST_SKIP() << "no AVX2 on this processor";
  PathGuard guard;
  Rng rng(12, 0);
  for (Eigen::Index n : {6, 33, 2048, 10001}) {
    for (int max_gap : {2, 5, 60, 100000}) {
      EnvelopeSpline lower(n + 16), upper(n + 16);
      FillValues(lower, NodeTimes(n, max_gap, rng), rng);
      FillValues(upper, NodeTimes(n, max_gap, rng), rng);
      FitPair(lower, upper);
      const Eigen::Index size = n + EnvelopeSpline::kPadding;
      Eigen::VectorXd h(size), lo_a(size), lo_b(size), next_a(size), next_b(size);
      for (Eigen::Index i = 0; i < size; ++i) h[i] = rng.Normal();
      SetSimdPath(SimdPath::kBaseline);
      lower.Evaluate(n, lo_a.data());
      upper.EvaluateSift(n, lo_a.data(), h.data(), next_a.data());
      SetSimdPath(SimdPath::kAvx2);
      lower.Evaluate(n, lo_b.data());
      upper.EvaluateSift(n, lo_b.data(), h.data(), next_b.data());
      EXPECT_TRUE(SameBits(lo_a.data(), lo_b.data(), n)) << n << " " << max_gap;
      EXPECT_TRUE(SameBits(next_a.data(), next_b.data(), n)) << n << " " << max_gap;
    }
  }
}

// Signals that exercise every branch of the scan: noise, exact zeros and runs of them,
// plateaus (zero differences), tiny values whose products underflow to -0, block edges.
std::vector<Eigen::VectorXd> ScanSignals() {
  Rng rng(13, 0);
  std::vector<Eigen::VectorXd> out;
  for (Eigen::Index n : {2, 3, 4, 63, 64, 65, 66, 129, 1000}) {
    Eigen::VectorXd x(n);
    for (Eigen::Index i = 0; i < n; ++i) x[i] = rng.Normal();
    out.push_back(x);
    Eigen::VectorXd z = x;
    for (Eigen::Index i = 0; i < n; i += 7) z[i] = 0.0;
    if (n > 10) z.segment(n / 2, 4).setZero();
    z[n - 1] = 0.0;
    out.push_back(z);
    Eigen::VectorXd p = x;
    for (Eigen::Index i = 0; i < n; ++i) p[i] = std::round(2.0 * x[i]);
    out.push_back(p);
    Eigen::VectorXd tiny = x * 1e-170;  // x[i] x[i+1] underflows: not a crossing for emd.m
    out.push_back(tiny);
  }
  return out;
}

TEST(SiftingSimd, ScanMatchesTheReferenceCounts) {
  PathGuard guard;
  for (int path = 0; path < 2; ++path) {
    SetSimdPath(path == 0 ? SimdPath::kBaseline : SimdPath::kAvx2);
    for (const Eigen::VectorXd& x : ScanSignals()) {
      const Eigen::Index n = x.size();
      std::vector<int> indmin(static_cast<size_t>(n) + 2), indmax(static_cast<size_t>(n) + 2);
      ExtremaScan scan;
      scan.indmin = indmin.data();
      scan.indmax = indmax.data();
      const bool flat = SimdFindStrictExtrema(x.data(), n, true, &scan);
      // Reference: the definitions, one sample at a time.
      int nmin = 0, nmax = 0;
      std::int64_t changes = 0;
      bool zero = false, zero_diff = false;
      for (Eigen::Index i = 0; i < n; ++i) {
        zero |= x[i] == 0.0;
        if (i + 1 < n) {
          changes += x[i] * x[i + 1] < 0.0;
          zero_diff |= x[i + 1] - x[i] == 0.0;
        }
        if (i == 0 || i + 1 >= n) continue;
        const double d0 = x[i] - x[i - 1], d1 = x[i + 1] - x[i];
        if (d0 > 0.0 && d1 < 0.0) {
          ASSERT_LT(nmax, scan.nmax);
          EXPECT_EQ(indmax[static_cast<size_t>(nmax++)], i);
        }
        if (d0 < 0.0 && d1 > 0.0) {
          ASSERT_LT(nmin, scan.nmin);
          EXPECT_EQ(indmin[static_cast<size_t>(nmin++)], i);
        }
      }
      EXPECT_EQ(scan.nmin, nmin) << n;
      EXPECT_EQ(scan.nmax, nmax) << n;
      EXPECT_EQ(scan.sign_changes, changes) << n;
      EXPECT_EQ(scan.has_zero, zero) << n;
      EXPECT_EQ(flat, zero_diff) << n;
    }
  }
}

TEST(SiftingSimd, RillingSiftMatchesTheScalarForm) {
  PathGuard guard;
  Rng rng(14, 0);
  for (int path = 0; path < 2; ++path) {
    SetSimdPath(path == 0 ? SimdPath::kBaseline : SimdPath::kAvx2);
    for (Eigen::Index n : {1, 3, 8, 1001}) {
      Eigen::VectorXd lo(n), hi(n), h(n), next(n), expected(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        lo[i] = rng.Normal();
        hi[i] = lo[i] + std::fabs(rng.Normal());
        h[i] = rng.Normal();
        // Touching envelopes: amplitude 0, ratio 0 / 0 (NaN) or x / 0 (infinite).
        if (i % 5 == 1) hi[i] = lo[i];
        if (i % 10 == 1) hi[i] = lo[i] = 0.0;
      }
      std::int64_t above1 = 0;
      bool above2 = false;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double mean = (lo[i] + hi[i]) / 2;
        const double amplitude = std::abs(hi[i] - lo[i]) / 2;
        const double ratio = std::abs(mean) / amplitude;
        above1 += ratio > 0.05;
        above2 |= ratio > 0.5;
        expected[i] = h[i] - mean;
      }
      const RillingCounts c =
          SimdRillingSift(lo.data(), hi.data(), h.data(), next.data(), n, 0.05, 0.5);
      EXPECT_EQ(c.above1, above1) << n;
      EXPECT_EQ(c.above2, above2) << n;
      EXPECT_TRUE(SameBits(next.data(), expected.data(), n)) << n;
    }
  }
}

TEST(SiftingSimd, SiftCountsDoNotDependOnThePath) {
  if (!SimdAvx2Available()) GTEST_SKIP() << "no AVX2 on this processor";
  PathGuard guard;
  for (StopRule rule : {StopRule::kSNumber, StopRule::kRilling}) {
    SiftingOptions options;
    options.stop_rule = rule;
    for (const Eigen::VectorXd& x : ScanSignals()) {
      const Eigen::Index n = x.size();
      if (n < 60) continue;
      Eigen::VectorXd a(n), b(n);
      SetSimdPath(SimdPath::kBaseline);
      Sifter sa(n, options);
      const SiftOutcome oa = sa.ExtractImf(x.data(), a.data());
      SetSimdPath(SimdPath::kAvx2);
      Sifter sb(n, options);
      const SiftOutcome ob = sb.ExtractImf(x.data(), b.data());
      EXPECT_EQ(oa.sifts, ob.sifts);
      EXPECT_EQ(oa.extracted, ob.extracted);
      if (oa.extracted) {
        EXPECT_TRUE(SameBits(a.data(), b.data(), n)) << n;
      }
    }
  }
}

}  // namespace
}  // namespace gyrodrift::decomposition::internal
