// Records and logged rows (records.h).
#include "gyrodrift/drift/records.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {

void RecordRows::Append(const Eigen::Ref<const Eigen::MatrixXd>& block,
                        const std::vector<Eigen::Index>& block_starts,
                        const std::vector<bool>& block_logged) {
  const Eigen::Index offset = rows.rows();
  if (offset > 0 && block.cols() != rows.cols()) {
    throw DataError("records of " + std::to_string(rows.cols()) + " and " +
                    std::to_string(block.cols()) + " columns cannot be joined");
  }
  if (!block_logged.empty() || !logged.empty()) {
    CheckLogged(block_logged, block.rows());
    logged.resize(static_cast<size_t>(offset), true);
    if (block_logged.empty()) {
      logged.resize(static_cast<size_t>(offset + block.rows()), true);
    } else {
      logged.insert(logged.end(), block_logged.begin(), block_logged.end());
    }
  }
  if (offset > 0) record_starts.push_back(offset);
  for (const Eigen::Index start : block_starts) record_starts.push_back(offset + start);
  rows.conservativeResize(offset + block.rows(), block.cols());
  rows.bottomRows(block.rows()) = block;
}

void CheckRecordStarts(const std::vector<Eigen::Index>& record_starts, Eigen::Index n) {
  Eigen::Index previous = 0;
  for (const Eigen::Index start : record_starts) {
    if (!(start > previous && start < n)) {
      throw DataError("record starts must increase strictly within (0, " + std::to_string(n) +
                      "): got " + std::to_string(start) + " after " + std::to_string(previous));
    }
    previous = start;
  }
}

void CheckLogged(const std::vector<bool>& logged, Eigen::Index n) {
  if (logged.empty()) return;
  if (static_cast<Eigen::Index>(logged.size()) != n) {
    throw DataError("the mask of logged rows has " + std::to_string(logged.size()) +
                    " flags for " + std::to_string(n) + " rows: they must match");
  }
  if (CountLogged(logged, n) == 0) throw DataError("the mask of logged rows marks no row logged");
}

Eigen::Index CountLogged(const std::vector<bool>& logged, Eigen::Index n) {
  if (logged.empty()) return n;
  return static_cast<Eigen::Index>(std::count(logged.begin(), logged.end(), true));
}

void RequireFiniteLogged(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                         const std::vector<bool>& logged, Eigen::Index min_samples) {
  if (logged.empty()) {
    RequireFiniteSignal(what, x, min_samples);
    return;
  }
  CheckLogged(logged, x.size());
  const Eigen::Index n = CountLogged(logged, x.size());
  if (n < min_samples) {
    throw DataError(std::string(what) + " has " + std::to_string(n) + " logged samples: at least " +
                    std::to_string(min_samples) + " are needed");
  }
  for (Eigen::Index r = 0; r < x.size(); ++r) {
    // As RequireFiniteSignal: only a bad sample pays for the call.
    if (logged[static_cast<size_t>(r)] && !(std::fabs(x[r]) <= kLargestSampleMagnitude)) {
      RequireUsableSample(what, r + 1, x[r], /*logged=*/true);
    }
  }
}

Eigen::MatrixXd LoggedRows(const Eigen::Ref<const Eigen::MatrixXd>& m,
                           const std::vector<bool>& logged) {
  if (logged.empty()) return m;
  CheckLogged(logged, m.rows());
  Eigen::MatrixXd out(CountLogged(logged, m.rows()), m.cols());
  Eigen::Index k = 0;
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    if (logged[static_cast<size_t>(r)]) out.row(k++) = m.row(r);
  }
  return out;
}

}  // namespace gyrodrift::drift
