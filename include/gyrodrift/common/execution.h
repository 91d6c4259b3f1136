// How a long library call runs, apart from what it computes: worker threads and a progress
// callback (which may also cancel the call). Every algorithm takes its options (plain values that
// decide the result: comparable, serialisable field by field) and, as a separate last argument,
// an Execution or a context struct that holds one (decomposition.h DecompositionContext, with the
// shared work of the EMD family). Nothing in an Execution changes a result: 1 and N threads give
// the same bits (common/parallel.h, common/random.h), and a progress callback only watches.
// Cost: none beyond the callback's own.
#pragma once

#include <functional>
#include <string_view>

namespace gyrodrift {

struct Execution {
  // Worker threads, in [0, 1024]; 0 (default) = every hardware core (ResolveThreads). Results do
  // not depend on it.
  int threads = 0;
  // Called with the fraction of the call done, in [0, 1] and not decreasing, and what is being
  // done (a short label such as "decompose"; each function documents its own, and may pass "").
  // Calls come in order and never concurrently, from the calling thread or a worker. May be empty
  // (default). To cancel the call, throw from it: the exception leaves the call (out of its
  // worker threads too) and nothing half-done is kept.
  std::function<void(double fraction, std::string_view step)> progress = {};

  // Calls progress if it is set.
  void Report(double fraction, std::string_view step) const {
    if (progress) progress(fraction, step);
  }
  void Validate() const;  // throws UsageError naming `threads`
};

// Throws UsageError "threads = <value>: must be an integer in [0, 1024] (0 = all cores)" unless
// threads is in range: the one check of every thread count (Execution, and the contexts of the
// study and the fleet calibration).
void ValidateThreads(int threads);

}  // namespace gyrodrift
