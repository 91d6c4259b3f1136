#include "gyrodrift/common/statistics.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace gyrodrift {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(Median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(Median({})));
}

// What MedianStep replaces: the median of a copy of the steps.
double MedianOfCopy(const Eigen::VectorXd& x) {
  std::vector<double> steps;
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) steps.push_back(x[i + 1] - x[i]);
  return Median(steps);
}

void ExpectSameBits(const Eigen::VectorXd& x, const std::string& label) {
  const double a = MedianOfCopy(x), b = MedianStep(x);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b))
      << label << ": copy " << a << ", selection " << b;
}

TEST(MedianStep, EqualsTheMedianOfTheCopiedStepsToTheBit) {
  EXPECT_TRUE(std::isnan(MedianStep(Eigen::VectorXd(0))));
  EXPECT_TRUE(std::isnan(MedianStep(Eigen::VectorXd::Constant(1, 3.0))));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> small(0, 3);
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Index n = 2 + trial % 37 + (trial % 5 == 0 ? 1000 : 0);  // odd and even counts
    Eigen::VectorXd x(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      switch (trial % 4) {
        case 0:  // a logger's time stamps: i / 100 (steps differ in their last bits)
          x[i] = static_cast<double>(i) / 100.0;
          break;
        case 1:  // few distinct steps: ties at the middle
          x[i] = (i ? x[i - 1] : 0.0) + 0.5 * small(rng);
          break;
        case 2:  // steps of both signs and many magnitudes
          x[i] = normal(rng) * std::exp2(small(rng) * 20 - 30);
          break;
        default:  // jittered stamps with repeats and steps back
          x[i] = static_cast<double>(i) + 0.6 * normal(rng);
      }
    }
    ExpectSameBits(x, "trial " + std::to_string(trial));
  }
  // Infinite steps, zero steps of both signs (the copy decides which zero), NaN steps.
  const double inf = std::numeric_limits<double>::infinity();
  ExpectSameBits((Eigen::VectorXd(3) << -1e308, 1e308, 1e308).finished(), "inf step");
  ExpectSameBits((Eigen::VectorXd(4) << -1e308, 1e308, -1e308, 1e308).finished(), "inf steps");
  ExpectSameBits((Eigen::VectorXd(4) << -0.0, 0.0, 0.0, -0.0).finished(), "signed zeros");
  ExpectSameBits((Eigen::VectorXd(5) << 1.0, 1.0, 2.0, 2.0, 3.0).finished(), "zero middle");
  ExpectSameBits((Eigen::VectorXd(3) << 0.0, inf, 1.0).finished(), "inf value");
}

}  // namespace
}  // namespace gyrodrift
