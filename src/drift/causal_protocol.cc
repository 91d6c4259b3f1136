// The causal protocol: each test sample's sub-series come from decomposing its trailing windows
// alone, each followed by its mirrored tail, and averaging their ends (CausalLags: a few
// decompositions per origin, origins in parallel, full windows of each length sharing one set of
// white-noise EMDs), its options (CausalOptions), and the note on sub-models a window is too
// short to feed (CausalWindowNote). PredictAhead (prediction.cc) runs it.
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

std::vector<Eigen::Index> CausalOptions::WindowLengths() const {
  std::vector<Eigen::Index> lengths;
  const Eigen::Index shortest = std::min(16, window);
  for (int j = 0; j < windows; ++j) {
    const double octaves = windows > 1 ? static_cast<double>(j) / (windows - 1) : 0.0;
    const Eigen::Index length =
        std::max(shortest, static_cast<Eigen::Index>(std::llround(window * std::exp2(-octaves))));
    if (lengths.empty() || lengths.back() != length) lengths.push_back(length);
  }
  return lengths;
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
  if (windows < 1 || windows > 16) {
    ThrowOption("windows", std::to_string(windows), "an integer in [1, 16]");
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
  // The origins run in parallel, each decomposition on its worker's thread.
  decomposition::DecompositionContext one_thread;
  one_thread.execution.threads = 1;
  // Every full window of one length has the same seed and ensemble, hence the same white-noise
  // EMDs: computed once here instead of once per window (the same bits; about half of each
  // window's cost), for as many lengths, longest first, as fit in 256 MB together (about
  // ensemble x log2(L) decomposed windows' worth of samples each, L = the window plus its
  // mirrored tail). Shared, the noise EMDs are computed to the end; a window computes only the
  // rows it uses (few, when BEEMDAN's bound stops early): sharing pays from a few windows on.
  const std::vector<Eigen::Index> lengths = causal.WindowLengths();
  std::vector<decomposition::DecompositionContext> shared_noise(lengths.size(), one_thread);
  const Eigen::Index last_origin = origin + count - 1;
  double cache_bytes = 0.0;
  for (size_t w = 0; w < lengths.size() && decomposition::UsesNoiseEmds(dopt.method); ++w) {
    const Eigen::Index full_windows = last_origin - std::max(origin, lengths[w]) + 1;
    const Eigen::Index decomposed = causal.DecomposedLength(lengths[w]);
    const double bytes = static_cast<double>(dopt.ensemble_size) *
                         decomposition::NoiseEmds::RowsPerRealisation(decomposed) *
                         static_cast<double>(decomposed) * sizeof(double);
    if (full_windows < 16 || cache_bytes + bytes > 256e6) continue;
    cache_bytes += bytes;
    shared_noise[w].noise_emds = std::make_shared<const decomposition::NoiseEmds>(
        decomposed, dopt, execution);  // its progress is not called
    assert(shared_noise[w].noise_emds->Matches(decomposed, dopt));
  }
  const int p = model.lags;
  const size_t groups = model.sub_models.size();
  std::vector<Eigen::MatrixXd> lags(groups, Eigen::MatrixXd::Zero(count, p));
  std::atomic<Eigen::Index> origins_done{0};
  std::mutex progress_mutex;
  double reported = 0.0;
  const Eigen::Index report_every = std::max<Eigen::Index>(1, count / 200);
  ParallelFor(static_cast<int>(count), execution.threads, [&](int r, int) {
    const Eigen::Index end = origin + r;  // the windows end just before the origin
    // Near the record's start the longer windows are cut to the same length: each length once.
    Eigen::Index previous = -1;
    int distinct = 0;  // window lengths decomposed at this origin
    for (size_t w = 0; w < lengths.size(); ++w) {
      const Eigen::Index length = std::min(lengths[w], end);
      if (length == previous) continue;
      previous = length;
      ++distinct;
      Eigen::VectorXd window(causal.DecomposedLength(length));
      window.head(length) = y.segment(end - length, length);
      window.tail(window.size() - length) =
          y.segment(end - 1 - (window.size() - length), window.size() - length).reverse();
      const Eigen::MatrixXd series = GroupSeries(
          model, decomposition::Decompose(window, dopt,
                                          length == lengths[w] ? shared_noise[w] : one_thread));
      for (size_t g = 0; g < groups; ++g) {
        for (int k = 0; k < p; ++k) {
          lags[g](r, k) += series(length - 1 - k, static_cast<Eigen::Index>(g));
        }
      }
    }
    for (size_t g = 0; g < groups; ++g) lags[g].row(r) /= static_cast<double>(distinct);
    const Eigen::Index done = ++origins_done;
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
  if (!UsesDecomposition(model.options.method) || causal.window < 2) return "";
  // The shortest window resolves the fewest IMFs; `windows` and `mirror` stay as given.
  const auto shortest_decomposed = [&causal](Eigen::Index w) {
    CausalOptions with_w = causal;
    with_w.window = static_cast<int>(std::min<Eigen::Index>(w, 1 << 30));
    return with_w.DecomposedLength(with_w.WindowLengths().back());
  };
  const std::vector<Eigen::Index> lengths = causal.WindowLengths();
  if (lengths.empty()) return "";  // windows < 1: refused by Validate
  const Eigen::Index window = lengths.back();
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
  // The least W whose shortest window's decomposed series has 2^(slowest + 1) samples: that
  // length does not decrease with W, so step from the estimate past the roundings and clamps.
  const auto target = static_cast<Eigen::Index>(std::ldexp(1.0, std::min(slowest + 1, 40)));
  auto needed = static_cast<Eigen::Index>(
      std::ceil(static_cast<double>(target) * causal.window / static_cast<double>(decomposed)));
  while (needed <= 1000000 && shortest_decomposed(needed) < target) ++needed;
  while (needed > 1 && shortest_decomposed(needed - 1) >= target) --needed;
  const size_t count = lengths.size();
  const std::string mirrored =
      decomposed > window ? std::to_string(decomposed) + " samples with its mirrored tail" : "";
  const std::string subject = count > 1
                                  ? "the shortest of the " + std::to_string(count) +
                                        " causal windows (" + std::to_string(window) + " samples" +
                                        (mirrored.empty() ? "" : "; " + mirrored) + ")"
                                  : "a " + std::to_string(window) + "-sample causal window" +
                                        (mirrored.empty() ? "" : " (" + mirrored + ")");
  return "note: " + subject + " resolves about " + std::to_string(resolved) + " IMFs; sub-model" +
         (several ? "s " : " ") + list + (several ? " hold" : " holds") +
         " slower ones, which fall into the window's residue: " +
         (several ? "they see" : "it sees") + " another series than in training (" +
         (needed > 1000000 ? "no window up to 1000000 samples resolves them"
          : count > 1      ? "window = " + std::to_string(needed) +
                            ", the longest of the windows, would resolve them"
                      : "a window of " + std::to_string(needed) + " samples would resolve them") +
         ")";
}

}  // namespace gyrodrift::drift
