// The selection criteria's curves and boundary rules (criteria.h) other than the PDF-similarity
// criterion's (pdf_similarity.cc): the energy curve with its white-noise band exit, and where the
// Komaty and energy-model criteria end the noise group.
#include "selection/criteria.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::selection::internal {

void AppendNote(std::string* note, const std::string& text) {
  if (!note->empty()) *note += "; ";
  *note += text;
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

void KomatyBoundaries(SelectionResult* result) {
  result->k_noise = result->k_star;
  result->mixed_end = result->k_star;
}

void EnergyModelBoundaries(SelectionResult* result) {
  result->k_noise = result->energy_signal_start - 1;
  result->mixed_end = result->k_noise;
}

}  // namespace gyrodrift::selection::internal
