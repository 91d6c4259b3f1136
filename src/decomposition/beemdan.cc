// BEEMDAN (METHOD.md section 3): ICEEMDAN's stages (iceemdan.cc) while the noise dominates, then
// plain EMD. The noise assistance ends by one of two policies: the first mode whose energy leaves
// the white-noise band (energy_band.h; the probe that finds it, the plain EMD mode of r_k, is kept
// as the first IMF of the plain EMD), or a fixed number of stages. BeemdanBound::kFull never ends
// it, which is ICEEMDAN itself.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "decomposition/drivers.h"
#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::decomposition::internal {
namespace {

// Ends the noise assistance at stage noise_stages.
NoiseStagePolicy FixedStages(const DecompositionOptions& o) {
  return [stages = o.noise_stages](int stage, std::vector<Eigen::VectorXd>&, Eigen::VectorXd&,
                                   Sifter&, Eigen::VectorXd&, DecompositionReport& report) {
    if (stage < stages) return true;
    report.stop_reason = "noise assistance ended after the requested " + std::to_string(stages) +
                         " stages; plain EMD for the rest";
    return false;
  };
}

// Ends the noise assistance at the first mode outside the white-noise energy band, whose band is
// set by mode 1 (modes[0], noise-assisted).
NoiseStagePolicy EnergyBandExit(const DecompositionOptions& o) {
  EnergyBand band;
  band.confidence = o.band_confidence;
  return [band](int stage, std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& r,
                Sifter& sifter, Eigen::VectorXd& imf, DecompositionReport& report) mutable {
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
    report.stop_reason = text;
    r -= imf;
    modes.push_back(imf);
    report.sifts_per_imf.push_back(probe.sifts);
    report.sift_cap_hit.push_back(probe.cap_hit);
    report.sift_cap_hits += probe.cap_hit;
    return false;
  };
}

}  // namespace

Decomposition RunBeemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job) {
  const DecompositionOptions& o = job.options;
  switch (o.beemdan_bound) {
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
