// BEEMDAN (METHOD.md section 3): ICEEMDAN's stages (iceemdan.cc) while the noise dominates, then
// plain EMD. The noise assistance ends by one of three policies: the first mode whose energy
// leaves the band of the ensemble's own white-noise modes (the default) or Flandrin et al.'s
// fitted band (energy_band.h; either way the probe that finds it, the plain EMD mode of r_k, is
// kept as the first IMF of the plain EMD), or a fixed number of stages.
// BeemdanBound::kFull never ends it, which is ICEEMDAN itself.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "decomposition/drivers.h"
#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::decomposition::internal {
namespace {

// Ends the noise assistance at stage noise_stages.
NoiseStagePolicy FixedStages(const DecompositionOptions& o) {
  return [stages = o.noise_stages](int stage, std::vector<Eigen::VectorXd>&, Eigen::VectorXd&,
                                   Sifter&, Eigen::VectorXd&, const NoiseEnergies&,
                                   DecompositionReport& report) {
    if (stage < stages) return true;
    report.stop_reason = "noise assistance ended after the requested " + std::to_string(stages) +
                         " stages; plain EMD for the rest";
    return false;
  };
}

// The probe outside the band ends the noise assistance: it is kept as the first IMF of the plain
// EMD that finishes the decomposition, and the report says why.
void KeepProbe(const char* reason, const SiftOutcome& probe, const Eigen::VectorXd& imf,
               Eigen::VectorXd& r, std::vector<Eigen::VectorXd>& modes,
               DecompositionReport& report) {
  report.stop_reason = reason;
  r -= imf;
  modes.push_back(imf);
  report.sifts_per_imf.push_back(probe.sifts);
  report.sift_cap_hit.push_back(probe.cap_hit);
  report.sift_cap_hits += probe.cap_hit;
}

// Ends the noise assistance at the first mode outside the white-noise energy band, whose band is
// set by mode 1 (modes[0], noise-assisted).
NoiseStagePolicy EnergyBandExit(const DecompositionOptions& o) {
  EnergyBand band;
  band.confidence = o.band_confidence;
  return [band](int stage, std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& r, Sifter& sifter,
                Eigen::VectorXd& imf, const NoiseEnergies&, DecompositionReport& report) mutable {
    if (stage == 1) band.log2_e1 = RobustLog2NoiseEnergy(modes.front());
    // Probe: the plain EMD mode of r_k. Outside the band it is the first signal mode, kept as
    // the first IMF of the plain EMD that finishes the decomposition.
    const SiftOutcome probe = sifter.ExtractImf(r.data(), imf.data());
    const int k = stage + 1;  // mode number under test
    const double log2_energy = std::log2(imf.squaredNorm());
    const double upper = band.Log2Upper(k);
    report.mode_log2_energy.push_back(log2_energy);
    report.noise_band_log2_upper.push_back(upper);
    if (band.Contains(k, log2_energy)) return true;
    char text[160];
    std::snprintf(text, sizeof(text),
                  "mode %d energy 2^%.2f above the %g%% white-noise band (2^%.2f); plain EMD for "
                  "the rest",
                  k, log2_energy, 100 * band.confidence, upper);
    KeepProbe(text, probe, imf, r, modes, report);
    return false;
  };
}

// Upper limit of the one-sided prediction interval at `confidence` for one more draw from the
// normal population the values sample: mean + t(confidence, n - 1) sd sqrt(1 + 1/n), the Student
// quantile by its Cornish-Fisher expansion (within 0.5 % of the exact one from 5 degrees of
// freedom on). An empirical 99 % quantile of 20 realisations would be their maximum, which one
// more draw exceeds one time in 21. NaN for fewer than 3 values.
double PredictionUpper(const std::vector<double>& values, double confidence) {
  const double n = static_cast<double>(values.size());
  if (values.size() < 3) return std::numeric_limits<double>::quiet_NaN();
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= n;
  double ss = 0.0;
  for (double v : values) ss += (v - mean) * (v - mean);
  const double sd = std::sqrt(ss / (n - 1.0));
  const double z = confidence == 0.99 ? 2.3263478740408408 : 1.6448536269514722;
  const double nu = n - 1.0;
  const double z2 = z * z, z3 = z2 * z, z5 = z3 * z2, z7 = z5 * z2;
  const double t = z + (z3 + z) / (4 * nu) + (5 * z5 + 16 * z3 + 3 * z) / (96 * nu * nu) +
                   (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * nu * nu * nu);
  return mean + t * sd * std::sqrt(1.0 + 1.0 / n);
}

// Ends the noise assistance at the first mode k >= 2 whose energy, relative to the robust noise
// energy of mode 1 (RobustLog2NoiseEnergy), is above the band of the same ratio over the
// ensemble's white-noise EMDs (mode k of realisation i against its own mode 1): the
// band_confidence prediction limit of log2 of that ratio. Those EMDs have the record's length and
// sifting, so the band holds at every mode the noise reaches, where the fitted band of Flandrin
// et al. widens without bound (docs/decomposition.md). As EnergyBandExit, the mode tested is the
// probe, the plain EMD mode of r_k, kept as the first plain mode when it is outside. With fewer
// than half of the realisations (or 3) reaching mode k the noise has no band there: that ends
// the noise assistance too.
NoiseStagePolicy EnsembleBandExit(const DecompositionOptions& o) {
  return [confidence = o.band_confidence, log2_e1 = 0.0](
             int stage, std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& r, Sifter& sifter,
             Eigen::VectorXd& imf, const NoiseEnergies& noise,
             DecompositionReport& report) mutable {
    if (stage == 1) log2_e1 = RobustLog2NoiseEnergy(modes.front());
    const int k = stage + 1;  // mode number under test
    std::vector<double> relative;
    for (const auto& ratios : noise.relative_log2) {
      if (static_cast<int>(ratios.size()) >= k) {
        relative.push_back(ratios[static_cast<size_t>(k - 1)]);
      }
    }
    const bool has_band = 2 * relative.size() >= noise.relative_log2.size() && relative.size() >= 3;
    const double upper = has_band ? log2_e1 + PredictionUpper(relative, confidence)
                                  : std::numeric_limits<double>::quiet_NaN();
    const SiftOutcome probe = sifter.ExtractImf(r.data(), imf.data());
    const double log2_energy = std::log2(imf.squaredNorm());
    report.mode_log2_energy.push_back(log2_energy);
    report.noise_band_log2_upper.push_back(upper);
    if (log2_energy <= upper) return true;
    char text[200];
    if (has_band) {
      std::snprintf(text, sizeof(text),
                    "mode %d energy 2^%.2f above the %g%% white-noise band of the ensemble's "
                    "mode %d (2^%.2f); plain EMD for the rest",
                    k, log2_energy, 100 * confidence, k, upper);
    } else {
      std::snprintf(text, sizeof(text),
                    "too few white-noise realisations have a mode %d (no band); plain EMD for "
                    "the rest",
                    k);
    }
    KeepProbe(text, probe, imf, r, modes, report);
    return false;
  };
}

}  // namespace

Decomposition RunBeemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job) {
  const DecompositionOptions& o = job.options;
  switch (o.beemdan_bound) {
    case BeemdanBound::kEnsembleBand:
      return RunIceemdanStages(x, job, EnsembleBandExit(o), /*noise_energies=*/true);
    case BeemdanBound::kEnergyBand:
      return RunIceemdanStages(x, job, EnergyBandExit(o));
    case BeemdanBound::kFixedStages:
      return RunIceemdanStages(x, job, FixedStages(o));
    case BeemdanBound::kFull:
      break;
  }
  return RunIceemdanStages(x, job, {});
}

}  // namespace gyrodrift::decomposition::internal
