// Decomposes a noisy two-tone signal with BEEMDAN and groups the IMFs, using the installed
// library. Prints one line per IMF and exits non-zero if the decomposition does not add up.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

int main() {
  const int n = 2048;
  gyrodrift::Rng rng(/*seed=*/42, /*stream=*/0);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) {
    x[i] = 0.3 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 256.0) + 0.001 * i;
  }
  gyrodrift::decomposition::DecompositionOptions options;  // BEEMDAN, Rilling stop, I = 100
  options.ensemble_size = 20;
  const auto d = gyrodrift::decomposition::Decompose(x, options);
  std::printf("%s\n", d.report.Summary().c_str());
  for (int k = 0; k < d.num_imfs(); ++k) {
    std::printf("imf%d rms %.4f\n", k + 1, std::sqrt(d.imfs.col(k).squaredNorm() / n));
  }
  const double error = (d.imfs.rowwise().sum() + d.residue - x).cwiseAbs().maxCoeff();
  return error < 1e-10 ? 0 : 1;
}
