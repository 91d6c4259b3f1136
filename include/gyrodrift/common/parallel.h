// Work sharing over a few threads with results that do not depend on the thread count.
//
// ParallelFor hands out task indices 0..n-1 in increasing order to `threads` workers.
// ParallelOrderedReduce additionally hands every task's result to `consume` exactly once, in
// index order and never concurrently, so floating-point sums come out the same bits for 1 and N
// threads. Tasks are handed out in order, so at most a few results wait to be consumed.
// The first exception thrown by a task stops the hand-out and is rethrown to the caller.
#pragma once

#include <functional>

namespace gyrodrift {

// Number of worker threads for a `threads` option: 0 means every hardware core.
int ResolveThreads(int threads);

// Calls body(task, worker) for task = 0..n-1, worker in [0, threads).
void ParallelFor(int n, int threads, const std::function<void(int task, int worker)>& body);

namespace internal {
// Type-erased core of ParallelOrderedReduce: produce(task, worker) stores its result in a slot
// keyed by task; consume(task) is called in index order on one thread at a time.
void OrderedReduce(int n, int threads, const std::function<void(int task, int worker)>& produce,
                   const std::function<void(int task)>& consume);
}  // namespace internal

// produce(task, worker) -> T runs in parallel; consume(task, T&&) runs in task order.
template <class Produce, class Consume>
void ParallelOrderedReduce(int n, int threads, Produce&& produce, Consume&& consume);

}  // namespace gyrodrift

#include "gyrodrift/common/parallel_impl.h"
