#include "gyrodrift/selection/noise_level.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"
#include "selection/density_scratch.h"

namespace gyrodrift::selection {

namespace {

constexpr double kInvSqrt2Pi = 0.39894228040143267794;
// The standardised grid always covers [-6, 6]: N(0, 1) leaves 2e-9 of its mass outside.
constexpr double kReferenceHalfWidth = 6.0;

// Type-7 quantile of a sorted vector.
double SortedQuantile(const std::vector<double>& sorted, double p) {
  const double pos = p * static_cast<double>(sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const double frac = pos - static_cast<double>(lo);
  if (lo + 1 >= sorted.size()) return sorted.back();
  return sorted[lo] + frac * (sorted[lo + 1] - sorted[lo]);
}

std::string Fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The level from G_k of R realisations (g[i][k - 1]; realisations may have different mode counts).
NoiseLevel LevelFromSamples(int length, double confidence, std::uint64_t seed,
                            const std::vector<std::vector<double>>& g) {
  size_t modes = 0;
  for (const auto& gi : g) modes = std::max(modes, gi.size());
  NoiseLevel out;
  out.length = length;
  out.realisations = static_cast<int>(g.size());
  out.confidence = confidence;
  out.seed = seed;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.level.assign(modes, nan);
  out.median.assign(modes, nan);
  out.mad.assign(modes, nan);
  out.family_scale.assign(modes, nan);
  out.realisations_with_mode.assign(modes, 0);
  std::vector<double> values;
  for (size_t k = 0; k < modes; ++k) {
    values.clear();
    for (const auto& gi : g) {
      if (k < gi.size()) values.push_back(gi[k]);
    }
    out.realisations_with_mode[k] = static_cast<int>(values.size());
    if (values.size() < static_cast<size_t>(kMinRealisationsPerMode)) continue;
    std::sort(values.begin(), values.end());
    out.level[k] = SortedQuantile(values, confidence);
    out.median[k] = SortedQuantile(values, 0.5);
    for (double& v : values) v = std::abs(v - out.median[k]);
    std::sort(values.begin(), values.end());
    out.mad[k] = SortedQuantile(values, 0.5);
  }
  // The family's statistic, realisation by realisation, over the modes with a level (a mode a
  // realisation lacks does not count; a mode without a level ends the run anyway). A deviation
  // above a zero MAD is unbounded.
  std::vector<double> running(g.size(), -std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < modes; ++k) {
    if (std::isnan(out.median[k])) {  // no level: the family's scale is that of the modes before
      if (k > 0) out.family_scale[k] = out.family_scale[k - 1];
      continue;
    }
    for (size_t i = 0; i < g.size(); ++i) {
      if (k >= g[i].size()) continue;
      const double deviation = g[i][k] - out.median[k];
      const double z = out.mad[k] > 0.0 ? deviation / out.mad[k]
                       : deviation > 0.0 ? std::numeric_limits<double>::infinity()
                                         : 0.0;
      running[i] = std::max(running[i], z);
    }
    values = running;
    std::sort(values.begin(), values.end());
    out.family_scale[k] = SortedQuantile(values, confidence);
  }
  return out;
}

std::string CacheKey(int length, const MonteCarloOptions& mc, const KdeOptions& kde,
                     PdfDistance distance) {
  const auto& s = mc.sifting;
  std::string key =
      std::to_string(length) + "|" + std::to_string(mc.realisations) + "|" + Fmt(mc.confidence) +
      "|" + std::to_string(mc.seed) + "|" + std::to_string(mc.max_imfs) + "|" +
      std::string(decomposition::ToString(s.stop_rule)) + "|" + Fmt(s.rilling_threshold1) + "|" +
      Fmt(s.rilling_threshold2) + "|" + Fmt(s.rilling_tolerance) + "|" +
      std::to_string(s.s_number) + "|" + std::to_string(s.fixed_sifts) + "|" + Fmt(s.sd_threshold) +
      "|" + std::to_string(s.max_sifts) + "|" + std::to_string(kde.grid_points) + "|" +
      Fmt(kde.points_per_bandwidth) + "|" + std::to_string(kde.max_grid_points) + "|" +
      Fmt(kde.bandwidth_scale) + "|" + Fmt(kde.padding_bandwidths) + "|" +
      std::string(ToString(kde.method)) + "|" + std::string(ToString(distance));
  return key;
}

}  // namespace

namespace internal {

double SelfSimilarity(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& kde,
                      PdfDistance distance, Scratch* scratch) {
  const Eigen::Index n = x.size();
  const double mean = x.mean();
  const double sd = std::sqrt((x.array() - mean).square().sum() / static_cast<double>(n - 1));
  if (!(sd > 0.0)) return std::numeric_limits<double>::infinity();
  // Silverman's rule is scale-equivariant: the bandwidth of (x - mean) / sd is h(x) / sd.
  const double h = kde.bandwidth_scale * SilvermanBandwidth(x, &scratch->kde) / sd;
  if (!(h > 0.0)) return std::numeric_limits<double>::infinity();
  const double z_min = (x.minCoeff() - mean) / sd;
  const double z_max = (x.maxCoeff() - mean) / sd;
  const double pad = kde.padding_bandwidths * h;
  const Grid grid = MakeGrid(std::min(z_min - pad, -kReferenceHalfWidth),
                             std::max(z_max + pad, kReferenceHalfWidth), h, kde);
  scratch->density.resize(grid.points);
  scratch->reference.resize(grid.points);
  EstimateDensity(x, mean, sd, h, grid, kde.method, &scratch->kde, scratch->density);
  const double s = std::sqrt(1.0 + h * h);
  for (int j = 0; j < grid.points; ++j) {
    const double u = grid.At(j) / s;
    scratch->reference[j] = std::exp(-0.5 * u * u) * kInvSqrt2Pi / s;
  }
  return Distance(distance, scratch->density, scratch->reference, grid.step);
}

}  // namespace internal

double SelfSimilarityDistance(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& kde,
                              PdfDistance distance) {
  kde.Validate();
  RequireFiniteSignal("x", x, 2);
  internal::Scratch scratch;
  return internal::SelfSimilarity(x, kde, distance, &scratch);
}

void MonteCarloOptions::Validate() const {
  if (realisations < 20 || realisations > 100000) {
    ThrowOption("realisations", std::to_string(realisations), "an integer in [20, 100000]");
  }
  if (!(confidence >= 0.5 && confidence < 1.0)) {
    ThrowOption("confidence", FormatValue(confidence), "in [0.5, 1)");
  }
  if (max_imfs < 0) ThrowOption("max_imfs", std::to_string(max_imfs), ">= 0 (0 = no cap)");
  ValidateNested("sifting", [&] { sifting.Validate(); });
}

double NoiseLevel::LevelFor(int k) const {
  if (k < 1 || k > static_cast<int>(level.size())) return std::numeric_limits<double>::quiet_NaN();
  return level[static_cast<size_t>(k - 1)];
}

double NoiseLevel::FamilyLevelFor(int k, int modes) const {
  if (k < 1 || k > modes || modes > static_cast<int>(family_scale.size())) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double m = median[static_cast<size_t>(k - 1)];
  const double spread = mad[static_cast<size_t>(k - 1)];
  if (!(spread > 0.0)) return m;  // NaN stays NaN
  return m + family_scale[static_cast<size_t>(modes - 1)] * spread;
}

std::string NoiseLevel::Summary() const {
  std::string s = "white-noise level N=" + std::to_string(length) +
                  " R=" + std::to_string(realisations) + " q=" + FormatValue(confidence) +
                  " seed=" + std::to_string(seed) + (partial ? " (reused noise EMDs)" : "") + ":";
  char buf[32];
  for (double v : level) {
    std::snprintf(buf, sizeof buf, " %.4g", v);
    s += buf;
  }
  return s;
}

NoiseLevel ComputeNoiseLevel(int length, const MonteCarloOptions& monte_carlo,
                             const KdeOptions& kde, PdfDistance distance,
                             const Execution& execution) {
  monte_carlo.Validate();
  kde.Validate();
  execution.Validate();
  if (length < 16) ThrowOption("length", std::to_string(length), ">= 16 samples");
  const int r = monte_carlo.realisations;
  const int workers = std::min(ResolveThreads(execution.threads), r);
  std::vector<internal::Scratch> scratch(static_cast<size_t>(workers));
  std::vector<Eigen::VectorXd> noise(static_cast<size_t>(workers), Eigen::VectorXd(length));
  std::vector<std::vector<double>> g(static_cast<size_t>(r));
  ParallelFor(r, workers, [&](int i, int w) {
    Eigen::VectorXd& x = noise[static_cast<size_t>(w)];
    Rng rng(monte_carlo.seed, static_cast<std::uint64_t>(i));
    rng.FillNormal(x);
    const decomposition::Decomposition d =
        decomposition::Emd(x, monte_carlo.sifting, monte_carlo.max_imfs);
    auto& gi = g[static_cast<size_t>(i)];
    gi.resize(static_cast<size_t>(d.num_imfs()));
    for (int k = 0; k < d.num_imfs(); ++k) {
      gi[static_cast<size_t>(k)] =
          internal::SelfSimilarity(d.imfs.col(k), kde, distance, &scratch[static_cast<size_t>(w)]);
    }
  });

  return LevelFromSamples(length, monte_carlo.confidence, monte_carlo.seed, g);
}

NoiseLevelCollector::NoiseLevelCollector(int length, const MonteCarloOptions& monte_carlo,
                                         const KdeOptions& kde, PdfDistance distance)
    : length_(length), monte_carlo_(monte_carlo), kde_(kde), distance_(distance) {
  monte_carlo_.Validate();
  kde_.Validate();
}

bool NoiseLevelCollector::Attach(const decomposition::DecompositionOptions& d,
                                 decomposition::DecompositionContext* context) {
  if (!decomposition::UsesNoiseEmds(d.method) || context->noise_imf_observer ||
      d.ensemble_size < monte_carlo_.realisations || !(d.sifting == monte_carlo_.sifting) ||
      monte_carlo_.max_imfs != 0 || length_ < 16) {
    return false;
  }
  attached_ = true;
  seed_ = d.seed;
  g_.assign(static_cast<size_t>(monte_carlo_.realisations), {});
  context->noise_imf_observer = [this](int realisation, [[maybe_unused]] int mode,
                                       const double* imf) {
    if (realisation >= monte_carlo_.realisations) return;
    // One realisation's modes arrive in order and never concurrently (the decomposition's
    // contract), so its slot needs no lock; the scratch is per thread.
    thread_local internal::Scratch scratch;
    auto& gi = g_[static_cast<size_t>(realisation)];
    assert(static_cast<int>(gi.size()) == mode - 1);
    gi.push_back(internal::SelfSimilarity(Eigen::Map<const Eigen::VectorXd>(imf, length_), kde_,
                                          distance_, &scratch));
  };
  return true;
}

std::shared_ptr<const NoiseLevel> NoiseLevelCollector::Level() const {
  if (!attached_) return nullptr;
  NoiseLevel level = LevelFromSamples(length_, monte_carlo_.confidence, seed_, g_);
  if (level.level.empty()) return nullptr;
  level.partial = true;
  return std::make_shared<const NoiseLevel>(std::move(level));
}

struct NoiseLevelCache::Impl {
  mutable std::mutex mutex;
  std::map<std::string, std::shared_future<std::shared_ptr<const NoiseLevel>>> entries;
};

NoiseLevelCache::NoiseLevelCache() : impl_(std::make_unique<Impl>()) {}
NoiseLevelCache::~NoiseLevelCache() = default;

std::shared_ptr<const NoiseLevel> NoiseLevelCache::Get(int length,
                                                       const MonteCarloOptions& monte_carlo,
                                                       const KdeOptions& kde, PdfDistance distance,
                                                       bool* computed, const Execution& execution) {
  monte_carlo.Validate();
  kde.Validate();
  execution.Validate();
  const std::string key = CacheKey(length, monte_carlo, kde, distance);
  std::promise<std::shared_ptr<const NoiseLevel>> promise;
  std::shared_future<std::shared_ptr<const NoiseLevel>> existing;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    auto it = impl_->entries.find(key);
    if (it != impl_->entries.end()) {
      existing = it->second;
    } else {
      impl_->entries.emplace(key, promise.get_future().share());
    }
  }
  if (existing.valid()) {
    // Waits (outside the lock) if another caller is still computing this key.
    if (computed != nullptr) *computed = false;
    return existing.get();
  }
  try {
    auto level = std::make_shared<const NoiseLevel>(
        ComputeNoiseLevel(length, monte_carlo, kde, distance, execution));
    promise.set_value(level);
    if (computed != nullptr) *computed = true;
    return level;
  } catch (...) {
    promise.set_exception(std::current_exception());
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->entries.erase(key);
    throw;
  }
}

void NoiseLevelCache::Clear() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->entries.clear();
}

std::size_t NoiseLevelCache::Size() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->entries.size();
}

NoiseLevelCache& NoiseLevelCache::Global() {
  static NoiseLevelCache cache;
  return cache;
}

}  // namespace gyrodrift::selection
