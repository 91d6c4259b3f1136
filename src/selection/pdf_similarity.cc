// The PDF-similarity criterion's boundaries (criteria.h; METHOD.md section 4, docs/selection.md
// section 2): k*, the peak of the distance D_k between the densities of the signal and of IMF k,
// and k_N, the run of modes 1..k* whose standardised densities stay within the white-noise level
// of G_k (noise_level.h). SelectModes (selection.cc) computes the densities and both curves.
#include <algorithm>
#include <memory>
#include <string>

#include "gyrodrift/selection/noise_level.h"
#include "selection/criteria.h"

namespace gyrodrift::selection::internal {

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
  // a few oscillations is far from Gaussian, so the level of late modes is wide enough to let a
  // slow drift mode through (docs/selection.md, section 2).
  const int judged = result->k_star;
  auto g = [&](int k) { return result->self_distance[static_cast<size_t>(k - 1)]; };
  // Modes 1..family are one test at the level's confidence (noise_level.h): testing each alone
  // at 99 % would end the run of a white record early in about 1 of 10 records of 11 modes. A
  // NaN level (the noise rarely had a mode k, or the level stops before it) ends the run.
  auto family_of = [&](const NoiseLevel& l) {
    return std::min(judged, static_cast<int>(l.family_scale.size()));
  };
  auto run_under = [&](const NoiseLevel& l, int family) {
    int run = 0;
    while (run < family && g(run + 1) <= l.FamilyLevelFor(run + 1, family)) ++run;
    return run;
  };
  int family = family_of(*level);
  int k_noise = run_under(*level, family);
  if (level->partial && k_noise == family && family < judged) {
    // The run outlasted a level collected from the decomposition: the whole family needs the
    // Monte-Carlo.
    AppendNote(&result->note, "white-noise level of modes 1.." + std::to_string(family) +
                                  " from the decomposition's noise (seed " +
                                  std::to_string(level->seed) +
                                  ") outlasted: modes 1..k* judged on the Monte-Carlo's");
    level =
        NoiseLevelCache::Global().Get(length, options.monte_carlo, options.kde, options.distance,
                                      &result->noise_level_computed, execution);
    family = family_of(*level);
    k_noise = run_under(*level, family);
  }
  // The curve: the family's level up to k*, past it each mode's as the last of a family 1..k.
  int run_past_k_star = 0;  // modes after k* under that level, reported only
  for (int k = 1; k <= k_count; ++k) {
    const double lk = level->FamilyLevelFor(k, std::max(k, family));
    result->noise_level.push_back(lk);
    if (k_noise == judged && k == judged + 1 + run_past_k_star && g(k) <= lk) ++run_past_k_star;
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
    if (run_past_k_star == 1) {
      text += " (mode " + std::to_string(judged + 1) +
              " also passes the white-noise test, left to the drift group)";
    } else if (run_past_k_star > 1) {
      text += " (modes " + std::to_string(judged + 1) + ".." +
              std::to_string(judged + run_past_k_star) +
              " also pass the white-noise test, left to the drift group)";
    }
    AppendNote(&result->note, text);
  }
}

}  // namespace gyrodrift::selection::internal
