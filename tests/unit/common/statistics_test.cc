#include "gyrodrift/common/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace gyrodrift {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(Median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(Median({})));
}

}  // namespace
}  // namespace gyrodrift
