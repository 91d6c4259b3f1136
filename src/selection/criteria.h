// Private: the selection criteria, one function per curve and per boundary rule, called by
// SelectModes once it has the densities and distances: the PDF-similarity criterion's in
// pdf_similarity.cc, the others in criteria.cc. The formulas and edge cases are
// in selection.h and docs/selection.md.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gyrodrift/selection/selection.h"

namespace gyrodrift::selection::internal {

// Appends `text` to a result's note, "; " between notes.
void AppendNote(std::string* note, const std::string& text);

// k* = the first maximum of D_k (1-based), pdf_distance[k - 1] = D_k, at least one entry.
int KStar(const std::vector<double>& pdf_distance);

// The energy curve of every criterion's result: log2 E_k of each IMF (N x K), the white-noise
// band's upper limit (energy_band.h; NaN for k = 1) and the band exit, the first mode k >= 2
// outside it (K + 1 if none). Sets log2_energy, energy_band_log2_upper, energy_signal_start.
void EnergyCurve(const Eigen::Ref<const Eigen::MatrixXd>& imfs, double band_confidence,
                 SelectionResult* result);

// The boundary rules: each sets k_noise and mixed_end of a result that holds the curves
// (num_imfs, pdf_distance, self_distance, k_star, energy_signal_start), and may add notes.

// kPdfSimilarity: k_N = the leading run of IMFs 1..k* with G_k under the white-noise level of
// `length`-sample records (options.noise_level, or NoiseLevelCache::Global(), which also completes
// a partial level the run outlasts); mixed_end = k*. Also sets noise_level,
// noise_level_realisations, noise_level_seed and noise_level_computed. A Monte-Carlo runs on the
// execution's threads.
void PdfSimilarityBoundaries(int length, const SelectionOptions& options,
                             const Execution& execution, SelectionResult* result);

// kKomaty: noise up to k*, no mixed group.
void KomatyBoundaries(SelectionResult* result);

// kEnergyModel: noise up to the mode before the band exit, no mixed group.
void EnergyModelBoundaries(SelectionResult* result);

}  // namespace gyrodrift::selection::internal
