// The white-noise energy band of Flandrin, Goncalves & Rilling (2004). The EMD of white noise
// gives mode energies that fall by a factor of about 2.01 per mode, E_k = E_1 / 0.719 * 2.01^-k,
// and log2 E_k stays below log2 of that model plus 2^(a k + b) with the stated confidence (a, b
// fitted by them for 95 % and 99 % only). BEEMDAN ends its noise assistance at the first mode
// above the band (METHOD.md section 3); the selection reports where the IMFs leave it.
#pragma once

#include <Eigen/Core>

namespace gyrodrift::decomposition {

// Throws the option error for `field` unless confidence is 0.95 or 0.99.
void ValidateBandConfidence(double confidence, const char* field = "band_confidence");

// log2 of the robust energy of the noise in mode 1, N (median|d_1| / 0.6745)^2: a few large
// signal samples in mode 1 do not move it. -inf when the median is 0.
double RobustLog2NoiseEnergy(const Eigen::Ref<const Eigen::VectorXd>& mode1);

struct EnergyBand {
  double log2_e1 = 0.0;       // RobustLog2NoiseEnergy of mode 1
  double confidence = 0.99;   // 0.95 or 0.99

  // The band's upper limit of log2 E_k for mode k >= 2.
  double Log2Upper(int k) const;
  // Mode k's energy E_k is inside the band (false for a NaN energy or log2_e1 = -inf).
  bool Contains(int k, double log2_energy) const { return log2_energy <= Log2Upper(k); }
};

}  // namespace gyrodrift::decomposition
