// Template part of parallel.h.
#pragma once

#include <map>
#include <mutex>
#include <optional>
#include <type_traits>
#include <utility>

namespace gyrodrift {

template <class Produce, class Consume>
void ParallelOrderedReduce(int n, int threads, Produce&& produce, Consume&& consume) {
  using T = std::decay_t<decltype(produce(0, 0))>;
  std::mutex mutex;
  std::map<int, T> pending;
  internal::OrderedReduce(
      n, threads,
      [&](int task, int worker) {
        T value = produce(task, worker);
        std::lock_guard<std::mutex> lock(mutex);
        pending.emplace(task, std::move(value));
      },
      [&](int task) {
        std::optional<T> value;
        {
          std::lock_guard<std::mutex> lock(mutex);
          auto it = pending.find(task);
          value.emplace(std::move(it->second));
          pending.erase(it);
        }
        consume(task, std::move(*value));
      });
}

}  // namespace gyrodrift
