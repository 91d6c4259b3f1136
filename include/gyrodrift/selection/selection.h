// Mode selection: groups the IMFs of a decomposition into noise, mixed and drift sub-series that
// add up to the signal.
//
// Criteria (docs/selection.md has the formulas and the edge cases):
//   kPdfSimilarity [reconstructed from Komaty, Boudraa, Augier & Dare-Emzivat, IEEE TIM 63(1)
//     2014; METHOD.md section 4]: Gaussian KDEs of the (centred) signal x and of every IMF on one
//     common grid; D_k = distance(pdf(x), pdf(IMF k)), k* = argmax D_k. G_k = distance of the
//     standardised IMF k to N(0, 1); k_N = length of the leading run of IMFs 1..k* with G_k under
//     the Monte-Carlo level of white-noise IMFs of the same length, modes 1..k* tested together
//     (the family-wise level, noise_level.h; cached): the run never passes k*.
//     noise = 1..k_N, mixed = k_N+1..k*, drift = k*+1..K plus the residue.
//   kKomaty: the two-way split of Komaty et al.: noise = 1..k*, drift = k*+1..K plus the residue.
//   kEnergyModel: white-noise IMF energy model of Flandrin, Goncalves & Rilling, IEEE SPL 11(2)
//     2004: E_k = E_1 / 0.719 * 2.01^-k with E_1 = N (median|imf_1| / 0.6745)^2; mode k >= 2 is
//     outside the 99 % band when log2 E(imf_k) > log2 E_k + 2^(0.46 k - 1.919) (95 %:
//     2^(0.474 k - 2.449)); the first such mode starts the drift group.
// Empty groups are dropped; the drift group always holds the residue. Each group's series is the
// sum of its IMF columns in increasing k, then the residue, so noise + mixed + drift equals
// sum_k imf_k + residue to round-off.
// Cost: K + 1 binned-FFT KDEs (milliseconds for N = 28,800) plus, for kPdfSimilarity, the
// Monte-Carlo level once per (N, options) per process (seconds; see noise_level.h). The densities
// and the Monte-Carlo run on the execution's threads; the result does not depend on them.
// Units: the group series have the units of x; D_k and G_k those of the chosen distance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/selection/distance.h"
#include "gyrodrift/selection/kde.h"
#include "gyrodrift/selection/noise_level.h"

namespace gyrodrift::selection {

enum class Criterion {
  kPdfSimilarity,  // three groups: noise / mixed / drift (default)
  kKomaty,         // two groups at k*: noise / drift
  kEnergyModel,    // two groups at the first mode outside the white-noise energy band
};
std::string_view ToString(Criterion criterion);
Criterion CriterionFromString(std::string_view name);  // "pdf", "komaty", "energy"

enum class GroupKind { kNoise, kMixed, kDrift };
std::string_view ToString(GroupKind kind);
GroupKind GroupKindFromString(std::string_view name);  // "noise", "mixed", "drift"

struct SelectionOptions {
  Criterion criterion = Criterion::kPdfSimilarity;
  PdfDistance distance = PdfDistance::kL2;  // for D_k and G_k (and the Monte-Carlo level)
  KdeOptions kde;                           // 512-point grid, Silverman bandwidth, binned FFT
  // Subtract mean(x) before comparing pdf(x) with the (zero-mean) IMF densities, so D_k compares
  // shapes and not the offset the residue carries [choice].
  bool center_signal = true;
  MonteCarloOptions monte_carlo;  // the white-noise level (kPdfSimilarity only)
  // A precomputed level (length must equal N), e.g. NoiseLevelCollector's; skips
  // NoiseLevelCache::Global() unless it is partial and the noise run outlasts it. It decides the
  // grouping like any option (== compares the pointer); a model file records only whether it was
  // given.
  std::shared_ptr<const NoiseLevel> noise_level;
  // kEnergyModel band: 0.99 (a = 0.46, b = -1.919) or 0.95 (a = 0.474, b = -2.449), the two
  // bands Flandrin et al. fitted; other values are rejected.
  double band_confidence = 0.99;

  void Validate() const;  // throws UsageError naming the field, value and allowed range
  bool operator==(const SelectionOptions&) const = default;
};

struct ModeGroup {
  GroupKind kind = GroupKind::kNoise;
  std::vector<int> imfs;     // member IMF indices k (1-based), increasing
  bool has_residue = false;  // the drift group holds the residue
  Eigen::VectorXd series;    // N samples: sum of the members (increasing k), then residue
};

struct SelectionResult {
  Criterion criterion = Criterion::kPdfSimilarity;
  PdfDistance distance = PdfDistance::kL2;
  int length = 0;    // N
  int num_imfs = 0;  // K
  // Curves, index k - 1 for IMF k.
  std::vector<double> pdf_distance;            // D_k = distance(pdf(x), pdf(IMF k))
  std::vector<double> self_distance;           // G_k = distance(pdf(standardised IMF k), N(0, 1))
  std::vector<double> noise_level;             // Monte-Carlo level of mode k (kPdfSimilarity only)
  std::vector<double> log2_energy;             // log2 sum_t imf_k(t)^2 (-inf for a zero IMF)
  std::vector<double> energy_band_log2_upper;  // white-noise band upper limit (NaN for k = 1)
  // Boundaries (IMF indices, 1-based; 0 = none).
  int k_star = 0;                 // argmax_k D_k (first maximum)
  int k_noise = 0;                // last noise IMF of the chosen criterion (k_N for kPdfSimilarity)
  int mixed_end = 0;              // last mixed IMF (kPdfSimilarity: k*; others: k_noise)
  int energy_signal_start = 0;    // first IMF outside the energy band (K + 1 if none)
  std::vector<ModeGroup> groups;  // the non-empty groups, in the order noise, mixed, drift
  // Diagnostics.
  int grid_points = 0;                // points of the common grid of x and the IMFs
  bool grid_under_resolved = false;   // the grid cap left a density below points_per_bandwidth
  double signal_bandwidth = 0.0;      // Silverman bandwidth of x (units of x)
  bool noise_level_computed = false;  // this call ran the Monte-Carlo (false: cache or supplied)
  // The white-noise level's realisations and seed (kPdfSimilarity; 0 otherwise): with the level
  // reused from a decomposition the seed is the decomposition's, not monte_carlo.seed.
  int noise_level_realisations = 0;
  std::uint64_t noise_level_seed = 0;
  // max_t |x - (sum_k imf_k + residue)| / max_t |x|: the groups add up to the decomposition's
  // reconstruction; for a non-complete decomposition (EEMD) that differs from x by this much.
  double reconstruction_error = 0.0;
  std::string note;  // edge cases met (e.g. "noise run reaches k*"), empty otherwise

  const ModeGroup* Group(GroupKind kind) const;  // nullptr when that group was dropped
  std::string Summary() const;                   // one line
};

// Groups the IMFs (N x K, K >= 1) and residue (N) of x (N >= 16 samples) on execution.threads
// workers (its progress is not called). Throws UsageError (bad options or threads, a supplied
// level of another length) or DataError (a non-finite sample, no IMF, mismatched sizes, a
// constant signal).
SelectionResult SelectModes(const Eigen::Ref<const Eigen::VectorXd>& x,
                            const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                            const Eigen::Ref<const Eigen::VectorXd>& residue,
                            const SelectionOptions& options = {}, const Execution& execution = {});
SelectionResult SelectModes(const Eigen::Ref<const Eigen::VectorXd>& x,
                            const decomposition::Decomposition& decomposition,
                            const SelectionOptions& options = {}, const Execution& execution = {});

// Decompose then SelectModes, with the pdf criterion's white-noise level taken from the
// decomposition's own noise EMDs where they are the Monte-Carlo's (NoiseLevelCollector): the way
// to group a signal's IMFs without paying for the Monte-Carlo a second time. A decomposition
// without IMF has no selection. The context serves both (its execution's progress reports the
// decomposition only); the collector adds its observer to it. Throws as Decompose and SelectModes
// do.
struct GroupedDecomposition {
  decomposition::Decomposition decomposition;
  std::optional<SelectionResult> selection;  // nullopt when the decomposition has no IMF
};
GroupedDecomposition DecomposeAndSelect(
    const Eigen::Ref<const Eigen::VectorXd>& x,
    const decomposition::DecompositionOptions& decomposition_options, SelectionOptions options,
    decomposition::DecompositionContext context = {});

}  // namespace gyrodrift::selection
