// Records: several runs of one calibration (chamber runs on different days), or one log split at
// its gaps, given one after the other as one series; and which rows of a log were logged rather
// than filled across a gap. Every model that runs states over time (the thermal lags, the feature
// lags) restarts them at a record's first row and fits on the logged rows only.
#pragma once

#include <Eigen/Core>
#include <string_view>
#include <vector>

namespace gyrodrift::drift {

// Several records (calibration runs, or a log split at its gaps) given one after the other, as
// one N-sample series: record_starts holds the first sample of every record after the first, and
// every lag restarts there. CheckRecordStarts throws DataError unless they increase strictly
// within (0, n); ForEachRecord calls f(begin, length) for each record in order.
void CheckRecordStarts(const std::vector<Eigen::Index>& record_starts, Eigen::Index n);
template <class F>
void ForEachRecord(Eigen::Index n, const std::vector<Eigen::Index>& record_starts, F&& f) {
  Eigen::Index begin = 0;
  for (const Eigen::Index start : record_starts) {
    f(begin, start - begin);
    begin = start;
  }
  f(begin, n - begin);
}

// Records appended one after another: each block of rows (N_i x C, the same C) below the earlier
// ones, record_starts gaining the block's first row (after the first block) and its own record
// starts shifted into place (the gaps of a log split at them), and logged its mask of logged rows
// (empty: every row; logged stays empty while every block's is).
struct RecordRows {
  Eigen::MatrixXd rows;
  std::vector<Eigen::Index> record_starts;
  std::vector<bool> logged;
  void Append(const Eigen::Ref<const Eigen::MatrixXd>& block,
              const std::vector<Eigen::Index>& block_starts = {},
              const std::vector<bool>& block_logged = {});
};

// Which rows of a record were logged (a log whose gaps were filled, io::GapPolicy::kCarry): one
// flag per row, true where the row was logged; empty = every row. The thermal states run over
// every row; fits and scores use the logged ones. CheckLogged throws DataError unless the mask is
// empty or has n flags with at least one set; LoggedRows keeps the rows of m where it is set.
void CheckLogged(const std::vector<bool>& logged, Eigen::Index n);
Eigen::MatrixXd LoggedRows(const Eigen::Ref<const Eigen::MatrixXd>& m,
                           const std::vector<bool>& logged);
// Rows logged: n when the mask is empty.
Eigen::Index CountLogged(const std::vector<bool>& logged, Eigen::Index n);
// RequireFiniteSignal (check.h) over the logged rows of x: at least min_samples of them, each
// usable (RequireUsableSample); one that is not is named by its row of the record ("<what> sample
// <row> (logged) is nan"), a made-up row may hold anything. With an empty mask, RequireFiniteSignal
// itself.
void RequireFiniteLogged(std::string_view what, const Eigen::Ref<const Eigen::VectorXd>& x,
                         const std::vector<bool>& logged, Eigen::Index min_samples);

}  // namespace gyrodrift::drift
