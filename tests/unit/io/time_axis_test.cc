// The time axis a log's reader keeps instead of time_s (CsvReadOptions::time_axis): its median step,
// smallest and largest steps and counts are those of the column itself, bit for bit.
#include "gyrodrift/io/time_axis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gyrodrift/common/random.h"
#include "gyrodrift/common/statistics.h"

namespace gyrodrift::io {
namespace {

TimeAxis AxisOf(const Eigen::VectorXd& t) {
  TimeAxis axis;
  for (Eigen::Index i = 0; i < t.size(); ++i) axis.Add(t[i]);
  return axis;
}

// i / 100 rounded to two decimals (as a logger prints it), with every 37th sample `early` s early:
// a few distinct steps, as real time stamps give.
Eigen::VectorXd Stamps(Eigen::Index n, double offset, double early) {
  Eigen::VectorXd t(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    t[i] = std::round((offset + static_cast<double>(i) / 100.0) * 100.0) / 100.0 -
           (i % 37 == 5 ? early : 0.0);
  }
  return t;
}

TEST(TimeAxis, StepsAreTheColumnsStepsBitForBit) {
  Rng rng(7, 0);
  for (const Eigen::Index n : {2, 3, 4, 5, 100, 101, 5000, 5001}) {
    for (const double offset : {0.0, 12345.67, 1e6}) {
      for (const double early : {0.0, 0.004, 0.0071}) {
        Eigen::VectorXd t = Stamps(n, offset, early);
        if (n > 50) t.tail(n - n / 2).array() += 0.5 * rng.Uniform();  // one odd step
        const TimeAxis axis = AxisOf(t);
        ASSERT_TRUE(axis.complete());
        ASSERT_TRUE(axis.increasing());
        EXPECT_EQ(axis.rows(), n);
        const double median = MedianStep(t);
        EXPECT_EQ(axis.MedianStep(), median) << n << " " << offset << " " << early;
        Eigen::Index below = 0, first = 0;
        double shortest = t[1] - t[0], largest = shortest;
        for (Eigen::Index i = 0; i + 1 < n; ++i) {
          const double step = t[i + 1] - t[i];
          if (step < 0.5 * median) ++below;
          if (step < shortest) {
            shortest = step;
            first = i;
          }
          largest = std::max(largest, step);
        }
        EXPECT_EQ(axis.StepsBelow(0.5 * median), below);
        EXPECT_EQ(axis.Shortest().value, shortest);
        EXPECT_EQ(axis.Shortest().first, first);
        EXPECT_EQ(axis.LargestStep(), largest);
        long double sum = 0.0L;
        Eigen::Index within = 0;
        for (Eigen::Index i = 0; i + 1 < n; ++i) {
          const double step = t[i + 1] - t[i];
          if (step >= 0.99 * median && step <= 1.01 * median) {
            sum += step;
            ++within;
          }
        }
        EXPECT_NEAR(axis.MeanStepWithin(0.99 * median, 1.01 * median),
                    static_cast<double>(sum / within), 1e-15 * median);
      }
    }
  }
}

TEST(TimeAxis, SaysWhenItCannotStandForTheColumn) {
  TimeAxis repeats = AxisOf((Eigen::VectorXd(4) << 0, 1, 1, 2).finished());
  EXPECT_TRUE(repeats.complete());
  EXPECT_FALSE(repeats.increasing());
  EXPECT_FALSE(AxisOf((Eigen::VectorXd(3) << 0, 2, 1).finished()).increasing());
  EXPECT_FALSE(
      AxisOf((Eigen::VectorXd(3) << 0, std::numeric_limits<double>::quiet_NaN(), 2).finished())
          .complete());
  EXPECT_FALSE(
      AxisOf((Eigen::VectorXd(2) << 0, std::numeric_limits<double>::infinity()).finished())
          .complete());
  // A jittery clock: every step its own value.
  TimeAxis jitter;
  double t = 0.0;
  for (size_t i = 0; i <= TimeAxis::kMaxDistinctSteps; ++i) {
    jitter.Add(t);
    EXPECT_TRUE(jitter.complete());
    t += 1.0 + static_cast<double>(i) * 1e-9;
  }
  jitter.Add(t);
  EXPECT_FALSE(jitter.complete());
  EXPECT_TRUE(jitter.increasing());
}

}  // namespace
}  // namespace gyrodrift::io
