// The ELM's dispatched row kernels (src/elm/elm_kernels.h), each table on its own: the documented
// order of operations to the bit, the vectorised exp against libm, row-position independence,
// and agreement of the AVX2 + FMA and baseline builds to rounding.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "elm/elm_kernels.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::elm::internal {
namespace {

// Every kernel table this machine can run: baseline always, AVX2 + FMA if the CPU has them.
std::vector<const Kernels*> Tables() {
  std::vector<const Kernels*> tables{&BaselineKernels()};
  if (Avx2Kernels() != nullptr) tables.push_back(Avx2Kernels());
  return tables;
}

bool UsesFma(const Kernels& k) { return std::string(k.name) == "avx2+fma"; }

bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

Eigen::MatrixXd RandomMatrix(Eigen::Index rows, Eigen::Index cols, double scale,
                             std::uint64_t seed) {
  Rng rng(seed, 0);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = scale * rng.Uniform(-1.0, 1.0);
  return m;
}

Eigen::MatrixXd Hidden(const Kernels& k, int activation, const Eigen::MatrixXd& x,
                       const Eigen::MatrixXd& w, const Eigen::VectorXd& b) {
  Eigen::MatrixXd out(x.rows(), w.cols());
  k.hidden(activation, x.data(), x.outerStride(), x.rows(), x.cols(), w.data(), b.data(), w.cols(),
           out.data(), out.outerStride());
  return out;
}

// Linear units and the output product follow the documented order exactly: start from the bias
// (or 0), add the products in index order, fused (one rounding) with FMA, else two roundings.
TEST(ElmKernels, LinearUnitsAndOutputsFollowTheDocumentedOrder) {
  const Eigen::MatrixXd x = RandomMatrix(37, 11, 3.0, 1);
  const Eigen::MatrixXd w = RandomMatrix(11, 9, 1.0, 2);
  const Eigen::VectorXd b = RandomMatrix(9, 1, 1.0, 3);
  const Eigen::MatrixXd beta = RandomMatrix(9, 2, 5.0, 4);
  for (const Kernels* k : Tables()) {
    auto mul_add = [&](double a, double c, double s) {
      return UsesFma(*k) ? std::fma(a, c, s) : a * c + s;
    };
    Eigen::MatrixXd z_ref(37, 9);
    for (int i = 0; i < 37; ++i) {
      for (int j = 0; j < 9; ++j) {
        double s = b[j];
        for (int q = 0; q < 11; ++q) s = mul_add(x(i, q), w(q, j), s);
        z_ref(i, j) = s;
      }
    }
    const Eigen::MatrixXd z = Hidden(*k, kKernelLinear, x, w, b);
    EXPECT_TRUE(SameBits(z, z_ref)) << k->name;

    Eigen::MatrixXd y_ref(37, 2);
    for (int i = 0; i < 37; ++i) {
      for (int m = 0; m < 2; ++m) {
        double s = 0.0;
        for (int j = 0; j < 9; ++j) s = mul_add(z(i, j), beta(j, m), s);
        y_ref(i, m) = s;
      }
    }
    Eigen::MatrixXd y(37, 2);
    k->output(z.data(), z.outerStride(), 37, 9, beta.data(), 2, y.data(), y.outerStride());
    EXPECT_TRUE(SameBits(y, y_ref)) << k->name;
  }
}

// The polynomial exp behind the sigmoid and RBF units against libm, over the whole range the
// units use and beyond (where the documented clamps apply).
TEST(ElmKernels, SigmoidAndRbfMatchLibmToAFewUlps) {
  std::vector<double> z;
  for (double v = -760.0; v <= 760.0; v += 0.37) z.push_back(v);
  for (double v = -3.0; v <= 3.0; v += 1.0 / 1024.0) z.push_back(v);
  for (double v : {-745.2, -708.4, -708.0, -40.0, -1e-300, 0.0, 1e-300, 36.7, 40.0, 41.0, 710.0}) {
    z.push_back(v);
  }
  const Eigen::Index n = static_cast<Eigen::Index>(z.size());
  const Eigen::MatrixXd x = Eigen::Map<const Eigen::VectorXd>(z.data(), n);
  const Eigen::MatrixXd one = Eigen::MatrixXd::Ones(1, 1);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  for (const Kernels* k : Tables()) {
    const Eigen::MatrixXd s = Hidden(*k, kKernelSigmoid, x, one, zero);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double expected = 1.0 / (1.0 + std::exp(-z[i]));
      if (z[i] < -708.0) {
        // Held at 1 / (1 + e^708) instead of decaying to the subnormal range.
        EXPECT_GE(s(i), expected) << z[i];
        EXPECT_LE(s(i), 3.4e-308) << z[i];
      } else {
        EXPECT_NEAR(s(i), expected, 4.0 * std::numeric_limits<double>::epsilon() * expected)
            << k->name << " z = " << z[i];
      }
    }
    // RBF with centre 0 and impact factor 1 on one input: exp(-x^2), for x^2 up to 800.
    const Eigen::MatrixXd xr = x / 27.0;
    const Eigen::MatrixXd r =
        Hidden(*k, kKernelRbf, xr, Eigen::MatrixXd::Zero(1, 1), Eigen::VectorXd::Ones(1));
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d2 = xr(i) * xr(i);
      const double expected = std::exp(-d2);
      if (d2 > 708.0) {
        // Held at e^-708.
        EXPECT_NEAR(r(i), std::exp(-708.0),
                    4.0 * std::numeric_limits<double>::epsilon() * std::exp(-708.0))
            << d2;
      } else {
        EXPECT_NEAR(r(i), expected, 4.0 * std::numeric_limits<double>::epsilon() * expected)
            << k->name << " x^2 = " << d2;
      }
    }
  }
}

// Each row of the hidden layer and of the output is the same bits computed in any block: alone,
// at every offset within a tile, at the ragged end.
TEST(ElmKernels, EveryRowIsTheSameBitsAloneAndInABlock) {
  const Eigen::MatrixXd x = RandomMatrix(53, 5, 2.0, 11);
  const Eigen::MatrixXd w = RandomMatrix(5, 7, 1.0, 12);
  const Eigen::VectorXd b = RandomMatrix(7, 1, 1.0, 13).array().abs();
  const Eigen::MatrixXd beta = RandomMatrix(7, 3, 1.0, 14);
  for (const Kernels* k : Tables()) {
    for (int activation : {kKernelSigmoid, kKernelTanh, kKernelSine, kKernelRbf, kKernelLinear}) {
      const Eigen::MatrixXd h = Hidden(*k, activation, x, w, b);
      Eigen::MatrixXd y(53, 3);
      k->output(h.data(), h.outerStride(), 53, 7, beta.data(), 3, y.data(), y.outerStride());
      for (Eigen::Index first = 0; first < 53; first += 3) {
        for (Eigen::Index count : {1, 2, 5, 9, 17}) {
          if (first + count > 53) continue;
          const Eigen::MatrixXd xb = x.middleRows(first, count);
          const Eigen::MatrixXd hb = Hidden(*k, activation, xb, w, b);
          EXPECT_TRUE(SameBits(hb, h.middleRows(first, count)))
              << k->name << " activation " << activation << " rows " << first << "+" << count;
          Eigen::MatrixXd yb(count, 3);
          k->output(hb.data(), hb.outerStride(), count, 7, beta.data(), 3, yb.data(),
                    yb.outerStride());
          EXPECT_TRUE(SameBits(yb, y.middleRows(first, count)))
              << k->name << " rows " << first << "+" << count;
        }
      }
    }
  }
}

// The two builds differ only by rounding (FMA or not): hidden layer, Gram matrix, and
// eigendecomposition agree to about 1e-13 relative.
TEST(ElmKernels, Avx2AndBaselineAgreeToRounding) {
  if (Avx2Kernels() == nullptr) GTEST_SKIP() << "this CPU has no AVX2 + FMA";
  const Kernels& base = BaselineKernels();
  const Kernels& avx = *Avx2Kernels();
  const Eigen::MatrixXd x = RandomMatrix(301, 16, 2.0, 21);
  const Eigen::MatrixXd w = RandomMatrix(16, 45, 1.0, 22);
  const Eigen::VectorXd b = RandomMatrix(45, 1, 1.0, 23).array().abs();
  for (int activation : {kKernelSigmoid, kKernelTanh, kKernelSine, kKernelRbf, kKernelLinear}) {
    const Eigen::MatrixXd h1 = Hidden(base, activation, x, w, b);
    const Eigen::MatrixXd h2 = Hidden(avx, activation, x, w, b);
    EXPECT_LT((h1 - h2).cwiseAbs().maxCoeff(), 1e-13 * (1.0 + h1.cwiseAbs().maxCoeff()))
        << activation;
  }
  const Eigen::MatrixXd h = Hidden(base, kKernelSigmoid, x, w, b);
  Eigen::MatrixXd g1(45, 45), g2(45, 45);
  base.gram(h.data(), 301, 301, 45, g1.data());
  avx.gram(h.data(), 301, 301, 45, g2.data());
  const Eigen::MatrixXd g_ref = h.transpose() * h;
  const Eigen::MatrixXd g1l = g1.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd g2l = g2.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd g_refl = g_ref.triangularView<Eigen::Lower>();
  EXPECT_LT((g1l - g_refl).norm(), 1e-13 * g_ref.norm());
  EXPECT_LT((g2l - g_refl).norm(), 1e-13 * g_ref.norm());

  Eigen::VectorXd v1(45), v2(45);
  Eigen::MatrixXd e1(45, 45), e2(45, 45);
  base.eigen(g1.data(), 45, 45, v1.data(), e1.data());
  avx.eigen(g1.data(), 45, 45, v2.data(), e2.data());
  EXPECT_LT((v1 - v2).cwiseAbs().maxCoeff(), 1e-12 * v1.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd full = g1.selfadjointView<Eigen::Lower>();
  EXPECT_LT((full * e2 - e2 * v2.asDiagonal()).norm(), 1e-12 * full.norm());
}

TEST(ElmKernels, ActiveTableIsTheBestTheCpuRuns) {
  const Kernels& active = ActiveKernels();
  EXPECT_EQ(&active, Avx2Kernels() != nullptr ? Avx2Kernels() : &BaselineKernels());
  EXPECT_EQ(KernelName(), active.name);
}

}  // namespace
}  // namespace gyrodrift::elm::internal
