// Self-similarity of noise: the distance G_k of a standardised IMF's density to N(0, 1), and the
// Monte-Carlo level that white-noise IMFs of the same length stay under.
//
// G_k = distance(KDE of (imf - mean) / sd, reference) on a grid covering the standardised
// samples and [-6, 6]. The reference is N(0, 1 + h^2), the expectation of a Gaussian KDE with
// bandwidth h of a N(0, 1) sample, so that the smoothing bias does not count as dissimilarity
// [choice]. A constant IMF has G_k = +inf (it is not noise).
//
// Level [reconstructed from Komaty et al., IEEE TIM 63(1) 2014, METHOD.md section 4]: R
// realisations of seeded white noise of length N (realisation i draws from Rng(seed, i)) are
// decomposed by plain EMD. Per mode, over the realisations that have a mode k (at least
// kMinRealisationsPerMode of them, else NaN: no level, the mode cannot be called noise): the
// `confidence` quantile (type 7) of G_k (`level`, mode k tested alone), its median and its median
// absolute deviation. The selection tests modes 1..m together [choice, docs/selection.md 2]: the
// family-wise level of mode k is median_k + c_m MAD_k, c_m the `confidence` quantile over the
// realisations of max_{k <= m} (G_k - median_k) / MAD_k, so that a white-noise decomposition
// passes all m modes with probability `confidence` (max-statistic simultaneous band), where the
// per-mode level fails about 10 % of white records over 11 modes. Realisations run on the execution's threads
// (ParallelFor); each fills its own slot, so the level is the same bits for any thread count.
// Cost: R plain EMDs of length N plus R * K KDEs, dominated by the EMDs: for N = 28,800 about
// 0.1 s of CPU per realisation, so R = 100 costs about 10 s of CPU (bench_selection).
// NoiseLevelCache keeps one level per (N, options) so a process pays this once.
// NoiseLevelCollector avoids the cost altogether after a CEEMDAN-family decomposition with at least
// R realisations: those already decompose R white-noise realisations of length N by plain EMD,
// so their IMFs are the Monte-Carlo's IMFs (the same bits when the seeds agree) and only the
// KDEs remain to be done.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gyrodrift/common/execution.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/selection/distance.h"
#include "gyrodrift/selection/kde.h"

namespace gyrodrift::selection {

// Distance of the standardised sample's KDE to N(0, 1 + h^2); +inf for a constant sample.
// x has >= 2 finite samples.
double SelfSimilarityDistance(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& kde,
                              PdfDistance distance);

struct MonteCarloOptions {
  int realisations = 100;    // white-noise realisations R, [20, 100000]
  double confidence = 0.99;  // quantile of G_k taken as the level, [0.5, 1)
  std::uint64_t seed = 1;    // realisation i draws from stream (seed, i)
  decomposition::SiftingOptions sifting;  // EMD of the noise realisations
  int max_imfs = 0;                       // EMD IMF cap, >= 0 (0 = until the residue is monotone)
  void Validate() const;                  // throws UsageError naming the field
  bool operator==(const MonteCarloOptions&) const = default;
};

constexpr int kMinRealisationsPerMode = 20;

struct NoiseLevel {
  int length = 0;        // N
  int realisations = 0;  // R
  double confidence = 0.0;
  std::uint64_t seed = 0;
  std::vector<double> level;   // level of mode k tested alone, at index k - 1 (NaN: no level)
  std::vector<double> median;  // median G_k of the white-noise mode k
  std::vector<double> mad;     // median |G_k - median_k| of the white-noise mode k
  // c_m at index m - 1: the confidence quantile of max_{k <= m} (G_k - median_k) / MAD_k.
  std::vector<double> family_scale;
  std::vector<int> realisations_with_mode;  // how many realisations had a mode k
  // The level covers modes 1..level.size() only: it was collected from a decomposition whose
  // white-noise EMDs stopped there (NoiseLevelCollector). Past them the level is unknown, not
  // absent; SelectModes then falls back to the Monte-Carlo.
  bool partial = false;
  // Level of mode k (1-based) tested alone; NaN beyond the modes the noise produced.
  double LevelFor(int k) const;
  // Level of mode k when modes 1..modes are tested together (k <= modes): median_k +
  // c_modes MAD_k (median_k when MAD_k = 0); NaN when either is unknown.
  double FamilyLevelFor(int k, int modes) const;
  std::string Summary() const;  // one line
};

// Runs the Monte-Carlo (no cache) on execution.threads workers (its progress is not called).
// length >= 16. Throws UsageError for bad options or threads.
NoiseLevel ComputeNoiseLevel(int length, const MonteCarloOptions& monte_carlo,
                             const KdeOptions& kde, PdfDistance distance,
                             const Execution& execution = {});

// The level of the white-noise IMFs a CEEMDAN-family decomposition computes anyway:
//   NoiseLevelCollector collector(n, selection.monte_carlo, selection.kde, selection.distance);
//   collector.Attach(decomposition_options, &context);  // before Decompose(x, options, context)
//   selection.noise_level = collector.Level();          // after it (nullptr if not attached)
// Realisations 0..R-1 of the decomposition play the Monte-Carlo's; their G_k are computed in the
// decomposition's worker threads as each noise IMF appears. The result equals ComputeNoiseLevel
// with the decomposition's seed (bit for bit) for the modes the decomposition reached, and is
// marked partial. The collector must outlive the Decompose call.
class NoiseLevelCollector {
 public:
  NoiseLevelCollector(int length, const MonteCarloOptions& monte_carlo, const KdeOptions& kde,
                      PdfDistance distance);
  // Installs the observer in the context of a decomposition with these options when its noise is
  // what the Monte-Carlo would use: a CEEMDAN-family method, at least R realisations, the
  // Monte-Carlo's sifting options and no IMF cap on its side, and no observer is installed yet.
  // Returns whether it did. For Decompose only: the noise DecomposeWithNoise is given is not the
  // Monte-Carlo's (drawn from (seed, i)), so its EMDs give no level of the seed.
  bool Attach(const decomposition::DecompositionOptions& decomposition,
              decomposition::DecompositionContext* context);
  // After the decomposition: the level of the modes it reached, or nullptr when not attached or
  // when no noise IMF was seen.
  std::shared_ptr<const NoiseLevel> Level() const;

 private:
  int length_;
  MonteCarloOptions monte_carlo_;
  KdeOptions kde_;
  PdfDistance distance_;
  bool attached_ = false;
  std::uint64_t seed_ = 0;
  std::vector<std::vector<double>> g_;  // G_k of realisation i's noise IMFs, in mode order
};

// Thread-safe cache of levels keyed by (length, every option). Concurrent callers asking for the
// same key wait for one computation. A failed computation is not cached.
class NoiseLevelCache {
 public:
  // The level for the key; *computed (if given) tells whether this call ran the Monte-Carlo (on
  // execution.threads workers).
  std::shared_ptr<const NoiseLevel> Get(int length, const MonteCarloOptions& monte_carlo,
                                        const KdeOptions& kde, PdfDistance distance,
                                        bool* computed = nullptr, const Execution& execution = {});
  void Clear();
  std::size_t Size() const;
  // The process-wide cache SelectModes uses.
  static NoiseLevelCache& Global();

  NoiseLevelCache();
  ~NoiseLevelCache();
  NoiseLevelCache(const NoiseLevelCache&) = delete;
  NoiseLevelCache& operator=(const NoiseLevelCache&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gyrodrift::selection
