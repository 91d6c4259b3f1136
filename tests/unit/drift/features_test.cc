// Records of one calibration (features.h): joined rows keep track of where each record starts,
// starts are checked, and every record is visited once, in order.
#include "gyrodrift/drift/features.h"

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {
namespace {

TEST(Records, AppendedBlocksShiftTheirOwnStarts) {
  RecordRows run;
  run.Append(Eigen::MatrixXd::Constant(3, 2, 1.0));
  run.Append(Eigen::MatrixXd::Constant(5, 2, 2.0), {2});  // a block split at its row 2
  run.Append(Eigen::MatrixXd::Constant(1, 2, 3.0));
  EXPECT_EQ(run.rows.rows(), 9);
  EXPECT_EQ(run.record_starts, (std::vector<Eigen::Index>{3, 5, 8}));
  EXPECT_EQ(run.rows(4, 1), 2.0);
  EXPECT_EQ(run.rows(8, 0), 3.0);
  EXPECT_THROW(run.Append(Eigen::MatrixXd::Zero(2, 3)), DataError);

  std::vector<std::pair<Eigen::Index, Eigen::Index>> seen;
  ForEachRecord(run.rows.rows(), run.record_starts,
                [&](Eigen::Index begin, Eigen::Index length) { seen.emplace_back(begin, length); });
  EXPECT_EQ(seen, (std::vector<std::pair<Eigen::Index, Eigen::Index>>{{0, 3}, {3, 2}, {5, 3}, {8, 1}}));
  EXPECT_NO_THROW(CheckRecordStarts(run.record_starts, 9));
  EXPECT_THROW(CheckRecordStarts({3, 3}, 9), DataError);
  EXPECT_THROW(CheckRecordStarts({0}, 9), DataError);
  EXPECT_THROW(CheckRecordStarts({9}, 9), DataError);
}

}  // namespace
}  // namespace gyrodrift::drift
