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
// decomposed by plain EMD; the level of mode k is the `confidence` quantile (type 7) of G_k over
// the realisations that have a mode k (at least kMinRealisationsPerMode of them, else NaN: no
// level, the mode cannot be called noise). Realisations run on `threads` workers (ParallelFor);
// each fills its own slot, so the level is the same bits for any thread count.
// Cost: R plain EMDs of length N plus R * K KDEs, dominated by the EMDs: for N = 28,800 about
// 0.1 s of CPU per realisation, so R = 100 costs about 10 s of CPU (bench_selection).
// NoiseLevelCache keeps one level per (N, options) so a process pays this once.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

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
  int threads = 0;           // workers, >= 0 (0 = every core); does not change the result
  decomposition::SiftingOptions sifting;  // EMD of the noise realisations
  int max_imfs = 0;                       // EMD IMF cap, >= 0 (0 = until the residue is monotone)
  void Validate() const;                  // throws UsageError naming the field
};

constexpr int kMinRealisationsPerMode = 20;

struct NoiseLevel {
  int length = 0;        // N
  int realisations = 0;  // R
  double confidence = 0.0;
  std::uint64_t seed = 0;
  std::vector<double> level;                // level of mode k at index k - 1 (NaN: no level)
  std::vector<double> median;               // median G_k of the white-noise mode k (diagnostic)
  std::vector<int> realisations_with_mode;  // how many realisations had a mode k
  // Level of mode k (1-based); NaN beyond the modes the noise produced.
  double LevelFor(int k) const;
  std::string Summary() const;  // one line
};

// Runs the Monte-Carlo (no cache). length >= 16. Throws UsageError for bad options.
NoiseLevel ComputeNoiseLevel(int length, const MonteCarloOptions& monte_carlo,
                             const KdeOptions& kde, PdfDistance distance);

// Thread-safe cache of levels keyed by (length, every option except threads). Concurrent callers
// asking for the same key wait for one computation. A failed computation is not cached.
class NoiseLevelCache {
 public:
  // The level for the key; *computed (if given) tells whether this call ran the Monte-Carlo.
  std::shared_ptr<const NoiseLevel> Get(int length, const MonteCarloOptions& monte_carlo,
                                        const KdeOptions& kde, PdfDistance distance,
                                        bool* computed = nullptr);
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
