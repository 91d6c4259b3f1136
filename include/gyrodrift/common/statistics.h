// Small order statistics shared across modules.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace gyrodrift {

// Median of the values (the mean of the two middle ones for an even count); NaN when empty.
// Takes a copy to reorder. Cost O(n).
double Median(std::vector<double> values);

// Median of the n - 1 steps x[i + 1] - x[i]: what Median gives for them, to the bit, without
// storing them (for the time stamps of a 1e8-sample log that copy is 800 MB). A radix selection
// on the steps' bit patterns, 16 bits a pass: five passes over x and a 512-KiB histogram. NaN
// when x has fewer than 2 values. Falls back to the copy where the order of the bit patterns and
// that of the values differ (a middle step of -0 or +0, a NaN step).
double MedianStep(const Eigen::Ref<const Eigen::VectorXd>& x);

}  // namespace gyrodrift
