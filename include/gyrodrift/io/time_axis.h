// What a log's checks need of its time column, gathered while the column is read, without its
// values (CsvReadOptions::time_axis): whether it increases, and its steps t[i+1] - t[i] as
// distinct values with their counts and first positions. A 1e8-row log's time_s costs 800 MB as
// a column; its steps are usually a handful of distinct values (the clock's step and its
// rounding), a few bytes in all.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <unordered_map>
#include <vector>

namespace gyrodrift::io {

class TimeAxis {
 public:
  // More distinct steps than this (a jittery clock) and the axis stops counting: complete() is
  // false and the caller reads the column whole instead. 65536 steps cost about 4 MB.
  static constexpr size_t kMaxDistinctSteps = size_t{1} << 16;

  // The next value of the column, in row order.
  void Add(double t);

  Eigen::Index rows() const { return rows_; }
  // Every value finite and every step counted (no more than kMaxDistinctSteps distinct ones).
  bool complete() const { return complete_; }
  // Every step > 0 (strictly increasing); true for fewer than 2 rows.
  bool increasing() const { return increasing_; }

  // The following need complete() and increasing(), and at least 2 rows.
  // MedianStep (common/statistics.h) of the values, bit for bit.
  double MedianStep() const;
  double LargestStep() const;
  // The number of steps below `limit`.
  Eigen::Index StepsBelow(double limit) const;
  // The mean of the steps in [lo, hi] (NaN when there are none).
  double MeanStepWithin(double lo, double hi) const;
  // The smallest step and the 0-based index i of its first occurrence (t[i+1] - t[i]).
  struct Step {
    double value = 0.0;
    Eigen::Index count = 0;
    Eigen::Index first = 0;
  };
  Step Shortest() const;

 private:
  void Count(double step);

  Eigen::Index rows_ = 0;
  double last_ = 0.0;
  bool complete_ = true;
  bool increasing_ = true;
  std::vector<Step> steps_;                     // in order of first occurrence
  std::unordered_map<double, size_t> index_;    // step value -> its entry in steps_
  size_t hit_ = 0;                              // the entry the last step matched
};

}  // namespace gyrodrift::io
