#include "gyrodrift/common/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "gyrodrift/common/random.h"

namespace gyrodrift {
namespace {

TEST(ParallelFor, VisitsEveryTaskOnce) {
  for (int threads : {1, 2, 4}) {
    std::vector<std::atomic<int>> hits(257);
    ParallelFor(257, threads, [&](int task, int worker) {
      ASSERT_LT(worker, threads);
      hits[task]++;
    });
    for (auto& h : hits) EXPECT_EQ(h.load(), 1);
  }
}

TEST(ParallelOrderedReduce, ConsumesInOrderAndSumIsThreadCountIndependent) {
  auto run = [](int threads) {
    std::vector<int> order;
    double sum = 0.0;
    ParallelOrderedReduce(
        300, threads,
        [](int task, int) {
          Rng rng(9, static_cast<std::uint64_t>(task));
          double s = 0;
          for (int i = 0; i < 1000 + (task % 7) * 500; ++i) s += rng.Normal() * 1e-3;
          return s;
        },
        [&](int task, double value) {
          order.push_back(task);
          sum += value;
        });
    for (int i = 0; i < 300; ++i) EXPECT_EQ(order[i], i);
    return sum;
  };
  const double one = run(1);
  EXPECT_EQ(one, run(2));
  EXPECT_EQ(one, run(3));
}

TEST(ParallelFor, RethrowsTheFirstError) {
  EXPECT_THROW(ParallelFor(50, 2,
                           [](int task, int) {
                             if (task == 17) throw std::runtime_error("task 17");
                           }),
               std::runtime_error);
}

TEST(ResolveThreads, ZeroMeansAllCores) {
  EXPECT_GE(ResolveThreads(0), 1);
  EXPECT_EQ(ResolveThreads(3), 3);
}

}  // namespace
}  // namespace gyrodrift
