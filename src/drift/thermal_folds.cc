#include "thermal_folds.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace gyrodrift::drift::internal {
namespace {

// Held-out regimes beyond this many are grouped with their neighbours (the search's cost grows
// with the folds).
constexpr int kMostRegimeFolds = 24;
// The range ends held out: the top and the bottom fifth of channel 0's span.
constexpr double kRangeEndShare = 0.2;

// A partition of the run into folds: contiguous groups of whole units (regimes or time blocks),
// cut at the unit boundaries nearest to i N / K, i = 1..K-1; each fold a range [first, last) of
// unit indices. Fewer folds when units are few.
std::vector<std::pair<int, int>> Partition(const std::vector<ThermalSegment>& segments,
                                           Eigen::Index n, int k) {
  std::vector<int> cuts{0};
  const int count = static_cast<int>(segments.size());
  for (int i = 1; i < k; ++i) {
    const double ideal = static_cast<double>(n) * i / k;
    int best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int j = 1; j < count; ++j) {
      const double d = std::abs(static_cast<double>(segments[static_cast<size_t>(j)].begin) - ideal);
      if (d < best_distance) {
        best_distance = d;
        best = j;
      }
    }
    if (best > cuts.back()) cuts.push_back(best);
  }
  cuts.push_back(count);
  std::vector<std::pair<int, int>> folds;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) folds.emplace_back(cuts[i], cuts[i + 1]);
  return folds;
}

// Equal time blocks as segments, for a run with too few regimes.
std::vector<ThermalSegment> TimeBlocks(Eigen::Index n, int k) {
  std::vector<ThermalSegment> blocks;
  k = static_cast<int>(std::min<Eigen::Index>(k, n / kShortestFold));
  for (int i = 0; i < k; ++i) blocks.push_back({n * i / k, n * (i + 1) / k, false});
  return blocks;
}

}  // namespace

std::vector<FoldRows> MakeFolds(const Eigen::Ref<const Eigen::VectorXd>& temperature_c,
                                          const std::vector<ThermalSegment>& segments,
                                          const Eigen::VectorXd& weight,
                                          const ThermalModelOptions& options) {
  const Eigen::Index n = temperature_c.size();
  std::vector<FoldRows> folds;
  std::vector<ThermalSegment> units = TimeBlocks(n, options.folds);
  if (options.folds_at_regimes && Partition(segments, n, options.folds).size() >= 3) {
    units = segments;
  }
  for (const auto& [first, last] : Partition(units, n, options.folds)) {
    folds.push_back({kTimeBlocks,
                     {{units[static_cast<size_t>(first)].begin,
                       units[static_cast<size_t>(last - 1)].end}}});
  }
  if (segments.size() >= 2) {
    for (const auto& [first, last] : Partition(segments, n, kMostRegimeFolds)) {
      folds.push_back({kRegimes,
                       {{segments[static_cast<size_t>(first)].begin,
                         segments[static_cast<size_t>(last - 1)].end}}});
    }
  }
  const double lo = temperature_c.minCoeff(), hi = temperature_c.maxCoeff();
  const double edge = kRangeEndShare * (hi - lo);
  for (bool top : {true, false}) {
    FoldRows f{kRangeEnds, {}};
    for (Eigen::Index i = 0; i < n; ++i) {
      const bool in = top ? temperature_c[i] >= hi - edge : temperature_c[i] <= lo + edge;
      if (!in) continue;
      if (!f.ranges.empty() && f.ranges.back().second == i) {
        f.ranges.back().second = i + 1;
      } else {
        f.ranges.emplace_back(i, i + 1);
      }
    }
    folds.push_back(std::move(f));
  }
  const double total = weight.sum();
  std::vector<FoldRows> kept;
  for (FoldRows& f : folds) {
    double logged = 0.0;
    for (const auto& [begin, end] : f.ranges) logged += weight.segment(begin, end - begin).sum();
    if (logged >= kShortestFold && total - logged >= kShortestFold) kept.push_back(std::move(f));
  }
  return kept;
}

}  // namespace gyrodrift::drift::internal
