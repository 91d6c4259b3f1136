// The EMD family: EMD, EEMD, CEEMDAN, ICEEMDAN and BEEMDAN behind one entry point.
//
// Computes x = sum_k imf_k + residue. Signals are Eigen vectors on a uniform time axis t = 1..N.
// References:
//   EMD      Huang et al., Proc. R. Soc. A 454 (1998); Rilling, Flandrin & Goncalves, NSIP 2003
//            (the defaults here reproduce their MATLAB emd.m).
//   EEMD     Wu & Huang, Adv. Adapt. Data Anal. 1 (2009).
//   CEEMDAN  Torres, Colominas, Schlotthauer & Flandrin, ICASSP 2011.
//   ICEEMDAN Colominas, Schlotthauer & Torres, Biomed. Signal Process. Control 14 (2014).
//   BEEMDAN  ICEEMDAN stages bounded to the noise-dominated early modes (Chen & Cui, Signal
//            Processing 128, 2016): by default the band of the ensemble's own white-noise mode
//            energies; or the noise model of Flandrin, Goncalves & Rilling, IEEE SPL 11 (2004).
// Cost: one sift is O(N); EMD is O(N * total sifts); the ensemble methods multiply the per-mode
// cost by the ensemble size I and spread realisations over the context's threads. Results are the
// same bits for any thread count (realisation i draws from stream (seed, i), sums run in i order).
// Units: the IMFs have the units of the input.
// DecompositionOptions are the plain values that decide the result (comparable with ==); how a
// decomposition runs (threads, progress, observers, shared noise EMDs) is its DecompositionContext,
// none of which changes a bit of the result.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"

namespace gyrodrift::decomposition {

enum class Method { kEmd, kEemd, kCeemdan, kIceemdan, kBeemdan };
std::string_view ToString(Method method);
// CEEMDAN, ICEEMDAN and BEEMDAN: the methods built on their realisations' white-noise EMDs
// (DecompositionContext::noise_imf_observer and noise_emds apply to them only).
bool UsesNoiseEmds(Method method);
Method MethodFromString(std::string_view name);  // "emd", "eemd", ...; throws UsageError

// When to stop sifting one IMF.
enum class StopRule {
  kRilling,   // Rilling-Flandrin: share of |mean|/amplitude > threshold1 under tolerance, none >
              // threshold2, and |#zero crossings - #extrema| <= 1
  kSNumber,   // Huang 2003 (libeemd's reading): extrema and zero-crossing counts change by at
              // most one for S consecutive sifts, and then differ from each other by at most one
  kFixed,     // exactly fixed_sifts sifts
  kCauchySd,  // Huang 1998: sum (h_prev - h)^2 / sum h_prev^2 < sd_threshold
};
std::string_view ToString(StopRule rule);
StopRule StopRuleFromString(std::string_view name);  // "rilling", "snumber", "fixed", "sd"

struct SiftingOptions {
  StopRule stop_rule = StopRule::kRilling;
  double rilling_threshold1 = 0.05;  // |mean|/amplitude level for the "most samples" test, (0, 1)
  double rilling_threshold2 = 0.5;   // |mean|/amplitude level no sample may exceed, >= threshold1
  double rilling_tolerance = 0.05;   // share of samples allowed above threshold1, [0, 1)
  int s_number = 4;                  // S of the S-number rule, >= 1
  int fixed_sifts = 10;              // sifts per IMF for kFixed, >= 1
  double sd_threshold = 0.2;         // Cauchy SD threshold, > 0
  // Sift cap per IMF, >= 1. 0 selects the rule's customary cap: 2000 (Rilling), 50 (S-number,
  // as libeemd), fixed_sifts (fixed), 2000 (SD).
  int max_sifts = 0;
  int EffectiveMaxSifts() const;
  void Validate() const;  // throws UsageError naming the field
  friend bool operator==(const SiftingOptions&, const SiftingOptions&) = default;
};

// How BEEMDAN decides how many stages get noise assistance.
enum class BeemdanBound {
  kEnergyBand,    // stop at the first mode whose energy leaves Flandrin et al.'s fitted band
  kFixedStages,   // exactly noise_stages noise-assisted stages
  kFull,          // every stage (then BEEMDAN equals ICEEMDAN bit for bit)
  kEnsembleBand,  // stop after the first mode whose energy leaves the band of the ensemble's own
                  // white-noise modes (the record's length and sifting; the default)
};
std::string_view ToString(BeemdanBound bound);
// "energy", "stages", "full", "ensemble"
BeemdanBound BeemdanBoundFromString(std::string_view name);

// ICEEMDAN noise scaling (the SNRFlag of the reference code).
enum class NoiseScaling {
  kColominas2014,  // SNRFlag 1: beta_k = eps * std(r_k), noise mode E_k(w) as is
  kConstantSnr,    // SNRFlag 2: E_k(w) divided by its std first
};
std::string_view ToString(NoiseScaling scaling);
NoiseScaling NoiseScalingFromString(std::string_view name);  // "colominas2014", "constant-snr"

class NoiseEmds;

struct DecompositionOptions {
  Method method = Method::kBeemdan;
  SiftingOptions sifting;
  int max_imfs = 0;  // cap on the IMF count (residue not counted), 0 = until the residue is
                     // monotone; EEMD with 0 uses floor(log2 N) - 1 so all members align
  // Noise-assisted methods.
  int ensemble_size = 100;      // I, in [1, 100000] (DecomposeWithNoise: the noise's columns)
  double noise_strength = 0.2;  // eps (EEMD: noise std / signal std; CEEMDAN family: eps_0)
  std::uint64_t seed = 1;       // realisation i draws from stream (seed, i)
  NoiseScaling noise_scaling = NoiseScaling::kColominas2014;
  // BEEMDAN.
  BeemdanBound beemdan_bound = BeemdanBound::kEnsembleBand;
  // 0.95 or 0.99: the quantile of the ensemble band, or which of the two bands Flandrin et al.
  // (2004) fitted
  double band_confidence = 0.99;
  int noise_stages = 3;           // for kFixedStages, >= 1

  void Validate() const;  // throws UsageError naming the field, value and allowed range
  bool operator==(const DecompositionOptions&) const = default;
};

// How one decomposition runs. Nothing here changes the result: the same options give the same
// bits with any context.
struct DecompositionContext {
  // threads: workers over the noise-assisted methods' realisations (an ensemble uses no more than
  // its realisations; plain EMD runs on the calling thread). progress: the noise-assisted methods
  // report the estimated fraction done, with the method's name as the step, from the thread that
  // accumulates the ensemble; plain EMD reports nothing.
  Execution execution = {};
  // CEEMDAN, ICEEMDAN, BEEMDAN: called with IMF `mode` (1-based) of white-noise realisation
  // `realisation`'s own EMD (unit variance, before any scaling; N samples) each time the method
  // extracts one, in increasing mode order per realisation, from the worker threads (calls for
  // different realisations may run concurrently; those for one realisation never do). Lets a
  // caller reuse these EMDs instead of computing its own (selection's white-noise level, see
  // selection::NoiseLevelCollector). May be empty (default).
  std::function<void(int realisation, int mode, const double* imf)> noise_imf_observer = {};
  // CEEMDAN, ICEEMDAN, BEEMDAN: the realisations' white-noise EMDs, computed beforehand for
  // signals of this length with this seed, ensemble size and sifting (see NoiseEmds) and shared
  // by many decompositions; Decompose refuses a set that does not match (or supplied noise).
  // Empty (default): each decomposition computes its own.
  std::shared_ptr<const NoiseEmds> noise_emds = {};
};

struct DecompositionReport {
  Method method = Method::kEmd;
  // EMD: sifts of IMF k; ensembles: mean over the realisations that sifted mode k.
  std::vector<int> sifts_per_imf;
  std::vector<bool> sift_cap_hit;  // IMF k hit the sift cap (any realisation)
  int sift_cap_hits = 0;           // total number of one-mode extractions that hit the cap
  int ensemble_size = 0;           // 0 for plain EMD
  std::uint64_t seed = 0;
  // Worker threads used (the context's execution.threads is the number asked for, 0 = every
  // core; an ensemble uses no more than its realisations). Not in Summary(): it never changes a
  // result.
  int threads = 1;
  bool supplied_noise = false;    // DecomposeWithNoise
  int noise_assisted_stages = 0;  // CEEMDAN family: stages run with noise
  std::string stop_reason;        // why the decomposition (or BEEMDAN's noise assistance) ended
  std::vector<double> mode_log2_energy;       // BEEMDAN: log2 energy of each tested mode
  std::vector<double> noise_band_log2_upper;  // BEEMDAN: the band's upper limit for that mode
  std::string Summary() const;                // one line
};

struct Decomposition {
  Eigen::MatrixXd imfs;     // N x K, one IMF per column
  Eigen::VectorXd residue;  // N
  DecompositionReport report;
  int num_imfs() const { return static_cast<int>(imfs.cols()); }
};

// The white-noise EMDs of an ensemble (realisation i drawn from stream (seed, i), unit variance)
// for signals of one length, each computed to the end once and then shared by every CEEMDAN,
// ICEEMDAN or BEEMDAN decomposition of that length with the same seed, ensemble size and sifting
// (DecompositionContext::noise_emds). The causal protocol decomposes thousands of windows of
// one length, and the noise EMDs are about half of each one's cost. Immutable once built, so
// one set may serve many threads; it holds ensemble x (IMFs + 2) x length doubles (the
// realisation, its IMFs and its residue).
class NoiseEmds {
 public:
  // Computes the EMDs with options' seed, ensemble_size and sifting on execution.threads workers
  // (its progress is not called). Throws UsageError for invalid options or threads, DataError for
  // a length under 4 samples.
  NoiseEmds(Eigen::Index length, const DecompositionOptions& options,
            const Execution& execution = {});

  struct Realisation {
    Eigen::VectorXd white;              // the realisation itself
    std::vector<Eigen::VectorXd> rows;  // its EMD as emd.m lists it: IMF 1, 2, ..., the residue
                                        // (left out when identically zero)
    int imfs = 0;                       // how many of the rows are IMFs
  };
  // Rows kept per realisation, as an estimate for memory: the realisation, about log2(length)
  // IMFs and the residue.
  static double RowsPerRealisation(Eigen::Index length) {
    return std::log2(static_cast<double>(length)) + 2.0;
  }
  Eigen::Index length() const { return length_; }
  int ensemble_size() const { return static_cast<int>(realisations_.size()); }
  const Realisation& realisation(int i) const { return realisations_[static_cast<size_t>(i)]; }
  // True when these EMDs are the ones a decomposition of n samples with o would compute.
  bool Matches(Eigen::Index n, const DecompositionOptions& o) const;

 private:
  Eigen::Index length_;
  std::uint64_t seed_;
  SiftingOptions sifting_;
  std::vector<Realisation> realisations_;
};

// The shortest signal with extrema to sift between: two ends and an interior maximum and minimum.
inline constexpr Eigen::Index kMinDecomposeSamples = 4;

// Decomposes x with options.method. Throws UsageError (bad options or context) or DataError
// (fewer than kMinDecomposeSamples samples, a non-finite sample).
Decomposition Decompose(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const DecompositionOptions& options,
                        const DecompositionContext& context = {});

// Decompose with supplied white noise instead of drawn: `noise` is N x I, one realisation per
// column (I = the ensemble size; options.ensemble_size is checked, not used), for the CEEMDAN
// family in the normalised domain x / std(x), for EEMD scaled by eps * std(x); e.g. the reference
// noise that reproduces the authors' MATLAB code. An input like x, not a context: it decides the
// result.
// Throws as Decompose, UsageError for method kEmd (which draws no noise) or with
// context.noise_emds, DataError for noise of the wrong shape or with a non-finite value.
Decomposition DecomposeWithNoise(const Eigen::Ref<const Eigen::VectorXd>& x,
                                 const Eigen::Ref<const Eigen::MatrixXd>& noise,
                                 const DecompositionOptions& options,
                                 const DecompositionContext& context = {});

// Plain EMD (the same as Decompose with Method::kEmd, without the ensemble fields).
Decomposition Emd(const Eigen::Ref<const Eigen::VectorXd>& x, const SiftingOptions& sifting = {},
                  int max_imfs = 0);

}  // namespace gyrodrift::decomposition
