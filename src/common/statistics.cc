#include "gyrodrift/common/statistics.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

namespace gyrodrift {

double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t mid = values.size() / 2;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(mid);
  std::nth_element(values.begin(), middle, values.end());
  double median = *middle;
  if (values.size() % 2 == 0) median = 0.5 * (median + *std::max_element(values.begin(), middle));
  return median;
}

namespace {

// A double's bits reordered so that unsigned order is the order of the values: negatives flipped
// whole, positives with the sign bit set. Exact for all but the zeros (-0 sorts just below +0).
std::uint64_t Key(double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  return bits >> 63 ? ~bits : bits | (std::uint64_t{1} << 63);
}

double FromKey(std::uint64_t key) {
  return std::bit_cast<double>(key >> 63 ? key & ~(std::uint64_t{1} << 63) : ~key);
}

// The k-th smallest step key (0-based): the top 16 bits from a histogram of every step's key,
// the next 16 from the steps that share them, and so on.
std::uint64_t KthStepKey(const Eigen::Ref<const Eigen::VectorXd>& x, std::uint64_t k,
                         std::vector<std::uint64_t>& histogram) {
  std::uint64_t prefix = 0, mask = 0;
  for (int shift = 48; shift >= 0; shift -= 16) {
    std::fill(histogram.begin(), histogram.end(), 0);
    for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
      const std::uint64_t key = Key(x[i + 1] - x[i]);
      if ((key & mask) == prefix) ++histogram[(key >> shift) & 0xFFFF];
    }
    std::uint64_t bucket = 0;
    while (k >= histogram[bucket]) k -= histogram[bucket++];
    prefix |= bucket << shift;
    mask |= std::uint64_t{0xFFFF} << shift;
  }
  return prefix;
}

double MedianOfStepCopy(const Eigen::Ref<const Eigen::VectorXd>& x) {
  std::vector<double> steps(static_cast<size_t>(x.size() - 1));
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) steps[static_cast<size_t>(i)] = x[i + 1] - x[i];
  return Median(std::move(steps));
}

}  // namespace

double MedianStep(const Eigen::Ref<const Eigen::VectorXd>& x) {
  if (x.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  // Finite values have no NaN step (inf - inf), whose place in nth_element's order is not a value's.
  if (!x.allFinite()) return MedianOfStepCopy(x);
  const std::uint64_t count = static_cast<std::uint64_t>(x.size() - 1);
  const std::uint64_t mid = count / 2;
  std::vector<std::uint64_t> histogram(std::size_t{1} << 16);
  const std::uint64_t key = KthStepKey(x, mid, histogram);
  const double upper = FromKey(key);
  if (upper == 0.0) return MedianOfStepCopy(x);  // which zero nth_element leaves there is its own
  if (count % 2 == 1) return upper;
  // The step just below in sorted order: `upper` again if fewer than mid steps are smaller, else
  // the largest smaller one. One more pass.
  std::uint64_t smaller = 0, below = 0;
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
    const std::uint64_t k = Key(x[i + 1] - x[i]);
    if (k < key) {
      ++smaller;
      below = std::max(below, k);
    }
  }
  const double lower = smaller < mid ? upper : FromKey(below);
  if (lower == 0.0) return MedianOfStepCopy(x);
  return 0.5 * (upper + lower);
}

}  // namespace gyrodrift
