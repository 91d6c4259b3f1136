#include "gyrodrift/io/time_axis.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gyrodrift::io {

void TimeAxis::Add(double t) {
  if (!std::isfinite(t)) complete_ = false;
  if (rows_++ == 0) {
    last_ = t;
    return;
  }
  const double step = t - last_;
  last_ = t;
  if (!(step > 0.0)) increasing_ = false;
  if (complete_) Count(step);
}

void TimeAxis::Count(double step) {
  // Consecutive steps mostly repeat one value: the last match is tried before the map.
  if (hit_ < steps_.size() && steps_[hit_].value == step) {
    ++steps_[hit_].count;
    return;
  }
  const auto found = index_.find(step);
  if (found != index_.end()) {
    hit_ = found->second;
    ++steps_[hit_].count;
    return;
  }
  if (steps_.size() == kMaxDistinctSteps) {
    complete_ = false;
    steps_ = {};
    index_ = {};
    return;
  }
  hit_ = steps_.size();
  index_.emplace(step, hit_);
  steps_.push_back({step, 1, rows_ - 2});
}

double TimeAxis::MedianStep() const {
  std::vector<Step> sorted = steps_;
  std::sort(sorted.begin(), sorted.end(),
            [](const Step& a, const Step& b) { return a.value < b.value; });
  // As MedianStep does: the mid-th smallest of the count = rows - 1 steps (0-based), and for an
  // even count the mean of it and the one below.
  const Eigen::Index count = rows_ - 1;
  const Eigen::Index mid = count / 2;
  auto kth = [&sorted](Eigen::Index k) {
    for (const Step& s : sorted) {
      if (k < s.count) return s.value;
      k -= s.count;
    }
    return sorted.back().value;
  };
  const double upper = kth(mid);
  if (count % 2 == 1) return upper;
  return 0.5 * (upper + kth(mid - 1));
}

double TimeAxis::LargestStep() const {
  double largest = steps_.front().value;
  for (const Step& s : steps_) largest = std::max(largest, s.value);
  return largest;
}

Eigen::Index TimeAxis::StepsBelow(double limit) const {
  Eigen::Index below = 0;
  for (const Step& s : steps_) {
    if (s.value < limit) below += s.count;
  }
  return below;
}

double TimeAxis::MeanStepWithin(double lo, double hi) const {
  long double sum = 0.0L;
  Eigen::Index within = 0;
  for (const Step& s : steps_) {
    if (s.value >= lo && s.value <= hi) {
      sum += static_cast<long double>(s.count) * s.value;
      within += s.count;
    }
  }
  return within > 0 ? static_cast<double>(sum / static_cast<long double>(within))
                    : std::numeric_limits<double>::quiet_NaN();
}

TimeAxis::Step TimeAxis::Shortest() const {
  Step shortest = steps_.front();
  for (const Step& s : steps_) {
    if (s.value < shortest.value) shortest = s;
  }
  return shortest;
}

}  // namespace gyrodrift::io
