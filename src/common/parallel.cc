#include "gyrodrift/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace gyrodrift {

int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

namespace internal {

void OrderedReduce(int n, int threads, const std::function<void(int, int)>& produce,
                   const std::function<void(int)>& consume) {
  if (n <= 0) return;
  const int workers = std::min(ResolveThreads(threads), n);
  std::atomic<int> next_task{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::exception_ptr first_error;
  std::vector<char> done(static_cast<size_t>(n), 0);
  int next_to_consume = 0;
  bool draining = false;

  auto record_error = [&](std::exception_ptr error) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!first_error) first_error = error;
    failed = true;
  };

  auto work = [&](int worker) {
    for (;;) {
      if (failed) return;
      const int task = next_task.fetch_add(1);
      if (task >= n) return;
      try {
        produce(task, worker);
      } catch (...) {
        record_error(std::current_exception());
        return;
      }
      // Whoever finds the next task in order ready drains the queue; the others move on.
      std::unique_lock<std::mutex> lock(mutex);
      done[static_cast<size_t>(task)] = 1;
      if (draining) continue;
      draining = true;
      while (next_to_consume < n && done[static_cast<size_t>(next_to_consume)] && !failed) {
        const int ready = next_to_consume++;
        lock.unlock();
        try {
          consume(ready);
        } catch (...) {
          record_error(std::current_exception());
        }
        lock.lock();
      }
      draining = false;
    }
  };

  if (workers == 1) {
    work(0);
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<size_t>(workers));
    for (int w = 0; w < workers; ++w) pool.emplace_back(work, w);
    for (auto& t : pool) t.join();
  }
  if (first_error) std::rethrow_exception(first_error);
  // A producer that finished after the last drainer left may have left tasks unconsumed.
  while (next_to_consume < n) consume(next_to_consume++);
}

}  // namespace internal

void ParallelFor(int n, int threads, const std::function<void(int, int)>& body) {
  internal::OrderedReduce(n, threads, body, [](int) {});
}

}  // namespace gyrodrift
