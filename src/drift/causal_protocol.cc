// The causal protocol: each test sample's sub-series come from decomposing its trailing window
// alone, followed by its mirrored tail (CausalLags: one decomposition per origin, windows in
// parallel, full windows sharing one set of white-noise EMDs), its options (CausalOptions), and
// the note on sub-models a window is too short to feed (CausalWindowNote). PredictAhead
// (prediction.cc) runs it.
#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "drift/prediction_steps.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift {

Eigen::Index CausalOptions::DecomposedLength(Eigen::Index length) const {
  assert(length >= 0);
  const Eigen::Index tail = std::llround(mirror * static_cast<double>(length));
  return length + std::clamp<Eigen::Index>(tail, 0, std::max<Eigen::Index>(0, length - 1));
}

void CausalOptions::Validate() const {
  if (window < 16 || window > 1000000) {
    ThrowOption("window", std::to_string(window), "an integer in [16, 1000000]");
  }
  if (ensemble_size < 0 || ensemble_size > 100000) {
    ThrowOption("ensemble_size", std::to_string(ensemble_size),
                "an integer in [0, 100000] (0 = the model's)");
  }
  if (!(mirror >= 0.0 && mirror <= 1.0)) {
    ThrowOption("mirror", FormatValue(mirror), "a share of the window in [0, 1]");
  }
}

namespace internal {

decomposition::DecompositionOptions DecompositionFor(const DriftModel& model) {
  decomposition::DecompositionOptions dopt = model.options.decomposition;
  dopt.seed = model.options.seed;
  return dopt;
}

std::vector<Eigen::MatrixXd> CausalLags(const DriftModel& model,
                                        const Eigen::Ref<const Eigen::VectorXd>& y,
                                        Eigen::Index origin, Eigen::Index count,
                                        const CausalOptions& causal, const Execution& execution) {
  decomposition::DecompositionOptions dopt = DecompositionFor(model);
  if (causal.ensemble_size > 0) dopt.ensemble_size = causal.ensemble_size;
  // The windows run in parallel, each decomposition on its worker's thread.
  decomposition::DecompositionContext one_thread;
  one_thread.execution.threads = 1;
  // Every full window has one length, seed and ensemble, hence the same white-noise EMDs:
  // computed once here instead of once per window (the same bits; about half of each window's
  // cost), when they take at most 256 MB (about ensemble x log2(L) decomposed windows' worth of
  // samples, L = W plus its mirrored tail).
  decomposition::DecompositionContext full_window = one_thread;
  const Eigen::Index last_origin = origin + count - 1;
  const Eigen::Index full_windows = last_origin - std::max<Eigen::Index>(origin, causal.window) + 1;
  const Eigen::Index full_length = causal.DecomposedLength(causal.window);
  const double cache_bytes = static_cast<double>(dopt.ensemble_size) *
                             decomposition::NoiseEmds::RowsPerRealisation(full_length) *
                             static_cast<double>(full_length) * sizeof(double);
  // Shared, the noise EMDs are computed to the end; a window computes only the rows it uses
  // (few, when BEEMDAN's bound stops early): sharing pays from a few windows on.
  if (decomposition::UsesNoiseEmds(dopt.method) && full_windows >= 16 && cache_bytes <= 256e6) {
    full_window.noise_emds = std::make_shared<const decomposition::NoiseEmds>(
        full_length, dopt, execution);  // its progress is not called
    assert(full_window.noise_emds->Matches(full_length, dopt));
  }
  const int p = model.lags;
  const size_t groups = model.sub_models.size();
  std::vector<Eigen::MatrixXd> lags(groups, Eigen::MatrixXd(count, p));
  std::atomic<Eigen::Index> windows_done{0};
  std::mutex progress_mutex;
  double reported = 0.0;
  const Eigen::Index report_every = std::max<Eigen::Index>(1, count / 200);
  ParallelFor(static_cast<int>(count), execution.threads, [&](int r, int) {
    const Eigen::Index end = origin + r;  // the window ends just before the origin
    const Eigen::Index start = std::max<Eigen::Index>(0, end - causal.window);
    const Eigen::Index length = end - start;
    Eigen::VectorXd window(causal.DecomposedLength(length));
    window.head(length) = y.segment(start, length);
    window.tail(window.size() - length) =
        y.segment(end - 1 - (window.size() - length), window.size() - length).reverse();
    const Eigen::MatrixXd series = GroupSeries(
        model,
        decomposition::Decompose(window, dopt, length == causal.window ? full_window : one_thread));
    for (size_t g = 0; g < groups; ++g) {
      for (int k = 0; k < p; ++k) {
        lags[g](r, k) = series(length - 1 - k, static_cast<Eigen::Index>(g));
      }
    }
    const Eigen::Index done = ++windows_done;
    if (execution.progress && (done % report_every == 0 || done == count)) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      const double fraction = static_cast<double>(done) / static_cast<double>(count);
      if (fraction > reported) {
        reported = fraction;
        execution.progress(fraction, "causal windows");
      }
    }
  });
  return lags;
}

}  // namespace internal

std::string CausalWindowNote(const DriftModel& model, const CausalOptions& causal) {
  const int window = causal.window;
  if (!UsesDecomposition(model.options.method) || window < 2) return "";
  const Eigen::Index decomposed = causal.DecomposedLength(window);
  const int resolved =
      std::max(1, static_cast<int>(std::floor(std::log2(static_cast<double>(decomposed)))) - 1);
  std::vector<std::string> names;
  int slowest = 0;
  for (const SubModel& sub : model.sub_models) {
    // The noise group's energy sits in its first IMFs (white noise loses about half per mode):
    // the slow ones it loses to the residue barely change its series.
    if (sub.has_residue || sub.imfs.empty() || sub.name == "noise") continue;
    const int last = *std::max_element(sub.imfs.begin(), sub.imfs.end());
    if (last <= resolved) continue;
    const int first = *std::min_element(sub.imfs.begin(), sub.imfs.end());
    names.push_back("'" + sub.name + "'" +
                    (first == last
                         ? ""
                         : " (IMFs " + std::to_string(first) + "-" + std::to_string(last) + ")"));
    slowest = std::max(slowest, last);
  }
  if (names.empty()) return "";
  std::string list = names.front();
  if (names.size() == 2) list += " and " + names.back();
  if (names.size() > 2) list += " ... " + names.back() + " (" + std::to_string(names.size()) + ")";
  const bool several = names.size() > 1;
  // The least window whose decomposed series has 2^(slowest + 1) samples: DecomposedLength does
  // not decrease with the window, so step from the estimate past the tail's rounding and clamp.
  const auto target = static_cast<Eigen::Index>(std::ldexp(1.0, std::min(slowest + 1, 40)));
  auto needed = static_cast<Eigen::Index>(
      std::ceil(static_cast<double>(target) * window / static_cast<double>(decomposed)));
  while (causal.DecomposedLength(needed) < target) ++needed;
  while (needed > 1 && causal.DecomposedLength(needed - 1) >= target) --needed;
  const std::string mirrored =
      decomposed > window ? " (" + std::to_string(decomposed) + " samples with its mirrored tail)"
                          : "";
  return "note: a " + std::to_string(window) + "-sample causal window" + mirrored +
         " resolves about " + std::to_string(resolved) + " IMFs; sub-model" +
         (several ? "s " : " ") + list + (several ? " hold" : " holds") +
         " slower ones, which fall into the window's residue: " +
         (several ? "they see" : "it sees") + " another series than in training (" +
         (needed <= 1000000
              ? "a window of " + std::to_string(needed) + " samples would resolve them"
              : "no window up to 1000000 samples resolves them") +
         ")";
}

}  // namespace gyrodrift::drift
