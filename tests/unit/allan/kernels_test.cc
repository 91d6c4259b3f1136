// The overlapping-ADEV kernel (src/allan/kernels.h): its blocked sums over consecutive averaging
// factors equal the direct sums.
#include "allan/kernels.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "unit/allan/white_noise.h"

namespace gyrodrift::allan {
namespace {

TEST(AllanKernels, BlockedSumsEqualDirectSums) {
  const Eigen::VectorXd x = WhiteNoise(10007, 1.0, 5);
  const std::vector<std::int64_t> ms = {1, 2, 3, 9, 40, 41, 200, 3000, 5003};
  std::vector<double> out(ms.size());
  internal::OverlappingSecondDifferenceSums(x.data(), x.size(), ms.data(),
                                            static_cast<int>(ms.size()), out.data());
  for (size_t k = 0; k < ms.size(); ++k) {
    const std::int64_t m = ms[k];
    long double ref = 0.0L;
    for (std::int64_t i = 0; i + 2 * m < x.size(); ++i) {
      const long double d = x[i + 2 * m] - 2.0L * x[i + m] + x[i];
      ref += d * d;
    }
    EXPECT_NEAR(out[k] / static_cast<double>(ref), 1.0, 1e-12) << m;
  }
}

}  // namespace
}  // namespace gyrodrift::allan
