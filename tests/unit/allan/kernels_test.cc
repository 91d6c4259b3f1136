// The estimator kernels (src/allan/kernels.h): the overlapping-ADEV sweep equals the direct sums
// and gives the same bits however the factors are split over calls; the batched noise
// identification gives IdentifyAlpha's answer at every factor.
#include "allan/kernels.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "gyrodrift/allan/edf.h"
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

TEST(AllanKernels, OneSweepOrSeveralGiveTheSameBits) {
  // A random walk (the phase of white rate noise) long enough for several chunks at the largest
  // factor, on an octave grid plus a run of consecutive factors (the four-factor path).
  Eigen::VectorXd x = WhiteNoise(50001, 1.0, 9);
  for (Eigen::Index i = 1; i < x.size(); ++i) x[i] += x[i - 1];
  std::vector<std::int64_t> ms = {1, 2, 3, 4, 5, 6, 8, 16, 32, 64, 128, 1024, 4096, 16384, 25000};
  const int count = static_cast<int>(ms.size());
  std::vector<double> all(ms.size());
  internal::OverlappingSecondDifferenceSums(x.data(), x.size(), ms.data(), count, all.data());
  for (int split = 1; split < count; split += 3) {
    std::vector<double> parts(ms.size());
    internal::OverlappingSecondDifferenceSums(x.data(), x.size(), ms.data(), split, parts.data());
    internal::OverlappingSecondDifferenceSums(x.data(), x.size(), ms.data() + split,
                                              count - split, parts.data() + split);
    for (int k = 0; k < count; ++k) EXPECT_EQ(parts[k], all[k]) << split << " " << ms[k];
  }
  for (int k = 0; k < count; ++k) {
    double one = 0.0;
    internal::OverlappingSecondDifferenceSums(x.data(), x.size(), &ms[k], 1, &one);
    EXPECT_EQ(one, all[k]) << ms[k];
  }
}

TEST(AllanKernels, BatchedNoiseIdentificationIsIdentifyAlphaAtEveryFactor) {
  // White rate noise (no differencing), its integral (random walk: the differencing stages) and
  // flicker-like sums of both, as rate and as angle data, over more than one sweep chunk.
  const Eigen::VectorXd w = WhiteNoise(20000, 1.0, 4);
  Eigen::VectorXd walk = w;
  for (Eigen::Index i = 1; i < walk.size(); ++i) walk[i] += walk[i - 1];
  const Eigen::VectorXd mixed = w + 0.05 * walk;
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; m <= 10000; m *= 2) ms.push_back(m);
  ms.push_back(3);
  ms.push_back(77);
  int identified = 0, differenced = 0;
  for (const Eigen::VectorXd* phase : std::vector<const Eigen::VectorXd*>{&w, &walk, &mixed}) {
    for (DataType type : {DataType::kRate, DataType::kAngle}) {
      for (int dmax : {2, 3}) {
        const auto batched = internal::IdentifyAlphas(*phase, ms, type, dmax);
        ASSERT_EQ(batched.size(), ms.size());
        for (size_t k = 0; k < ms.size(); ++k) {
          const auto single = IdentifyAlpha(*phase, ms[k], type, dmax);
          EXPECT_EQ(batched[k], single) << ms[k];
          identified += single.has_value();
          differenced += single.has_value() && *single < (type == DataType::kRate ? -1 : 1);
        }
      }
    }
  }
  EXPECT_GT(identified, 50);
  EXPECT_GT(differenced, 10);  // the fall-back to the differencing stages was exercised
}

}  // namespace
}  // namespace gyrodrift::allan
