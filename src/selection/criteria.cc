// The selection criteria's curves and boundary rules (criteria.h): k*, the energy curve with its
// white-noise band exit, and where each criterion ends the noise and mixed groups.
#include "selection/criteria.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "gyrodrift/decomposition/energy_band.h"
#include "gyrodrift/selection/noise_level.h"

namespace gyrodrift::selection::internal {

void AppendNote(std::string* note, const std::string& text) {
  if (!note->empty()) *note += "; ";
  *note += text;
}

int KStar(const std::vector<double>& pdf_distance) {
  const int k_count = static_cast<int>(pdf_distance.size());
  int k_star = 1;
  for (int k = 2; k <= k_count; ++k) {
    if (pdf_distance[static_cast<size_t>(k - 1)] > pdf_distance[static_cast<size_t>(k_star - 1)]) {
      k_star = k;
    }
  }
  return k_star;
}

// The white-noise band of Flandrin, Goncalves & Rilling (2004), with the same robust mode-1
// energy as BEEMDAN.
void EnergyCurve(const Eigen::Ref<const Eigen::MatrixXd>& imfs, double band_confidence,
                 SelectionResult* result) {
  const int k_count = static_cast<int>(imfs.cols());
  decomposition::EnergyBand band;
  band.confidence = band_confidence;
  band.log2_e1 = decomposition::RobustLog2NoiseEnergy(imfs.col(0));
  result->energy_signal_start = k_count + 1;
  for (int k = 1; k <= k_count; ++k) {
    const double log2_energy = std::log2(imfs.col(k - 1).squaredNorm());
    result->log2_energy.push_back(log2_energy);
    if (k == 1) {
      result->energy_band_log2_upper.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    result->energy_band_log2_upper.push_back(band.Log2Upper(k));
    // A zero mode 1 (median 0) gives log2 E_1 = -inf: every later mode is outside the band.
    if (result->energy_signal_start == k_count + 1 && !band.Contains(k, log2_energy)) {
      result->energy_signal_start = k;
    }
  }
}

void PdfSimilarityBoundaries(int length, const SelectionOptions& options,
                             const Execution& execution, SelectionResult* result) {
  const int k_count = result->num_imfs;
  std::shared_ptr<const NoiseLevel> level = options.noise_level;
  if (!level) {
    level =
        NoiseLevelCache::Global().Get(length, options.monte_carlo, options.kde, options.distance,
                                      &result->noise_level_computed, execution);
  }
  // The noise run is judged up to k* only (Komaty et al.: the modes up to the D peak are the
  // noise-dominated ones). Past it the test cannot tell noise from drift: a white-noise IMF with
  // a few oscillations is far from Gaussian, so the 99 % level of late modes is wide enough to
  // let a slow drift mode through (docs/selection.md, section 2).
  const int judged = result->k_star;
  int k_noise = 0;
  int run_past_k_star = 0;  // modes after k* under the level, reported only
  for (int k = 1; k <= k_count; ++k) {
    if (level->partial && k > static_cast<int>(level->level.size()) && k_noise == k - 1 &&
        k <= judged) {
      // The noise run outlasted a level collected from the decomposition: the rest needs
      // the Monte-Carlo (modes 1..k-1 agree with it when the seeds do).
      AppendNote(&result->note, "white-noise level of modes 1.." + std::to_string(k - 1) +
                                    " from the decomposition's noise (seed " +
                                    std::to_string(level->seed) +
                                    "), later modes from the Monte-Carlo");
      level =
          NoiseLevelCache::Global().Get(length, options.monte_carlo, options.kde, options.distance,
                                        &result->noise_level_computed, execution);
    }
    const double lk = level->LevelFor(k);
    result->noise_level.push_back(lk);
    // A NaN level (the noise rarely had a mode k) or G_k above it ends the run.
    const bool under = result->self_distance[static_cast<size_t>(k - 1)] <= lk;
    if (k_noise == k - 1 && k <= judged && under) {
      k_noise = k;
    } else if (k_noise == judged && k == judged + 1 + run_past_k_star && under) {
      ++run_past_k_star;
    }
  }
  result->k_noise = k_noise;
  result->noise_level_realisations = level->realisations;
  result->noise_level_seed = level->seed;
  if (level->partial && static_cast<int>(level->level.size()) < k_count) {
    AppendNote(&result->note,
               "white-noise level reused from the decomposition's noise EMDs, "
               "known for modes 1.." +
                   std::to_string(level->level.size()));
  }
  result->mixed_end = result->k_star;
  if (k_noise == 0) AppendNote(&result->note, "no IMF passes the white-noise test: no noise group");
  if (k_noise == result->k_star) {
    std::string text = "noise run reaches k*: no mixed group";
    if (run_past_k_star > 0) {
      text += " (modes " + std::to_string(judged + 1) + ".." +
              std::to_string(judged + run_past_k_star) +
              " also pass the white-noise test, left to the drift group)";
    }
    AppendNote(&result->note, text);
  }
}

void KomatyBoundaries(SelectionResult* result) {
  result->k_noise = result->k_star;
  result->mixed_end = result->k_star;
}

void EnergyModelBoundaries(SelectionResult* result) {
  result->k_noise = result->energy_signal_start - 1;
  result->mixed_end = result->k_noise;
}

}  // namespace gyrodrift::selection::internal
