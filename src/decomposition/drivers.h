// Private: the per-method drivers behind Decompose() (one file each: emd.cc, eemd.cc,
// ceemdan.cc, iceemdan.cc, beemdan.cc) and the incremental white-noise EMD.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "decomposition/sifting.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition::internal {

// What a driver reads: the options, the caller's context and, for DecomposeWithNoise, the
// supplied noise (N x I; null: realisation i is drawn from stream (seed, i)). Decompose has
// checked all three against each other and against the signal.
struct Job {
  const DecompositionOptions& options;
  const DecompositionContext& context;
  const Eigen::Ref<const Eigen::MatrixXd>* noise = nullptr;
  int threads() const { return context.execution.threads; }
};

// The EMD of one white-noise realisation, extracted one mode at a time on demand, so the
// CEEMDAN family never computes a noise mode it does not use nor recomputes one from the start.
// Rows follow emd.m: IMF 1, IMF 2, ..., then the residue (if not identically zero).
class NoiseModes {
 public:
  // Takes the realisation (moved in; it becomes the running residue).
  explicit NoiseModes(Eigen::VectorXd noise);
  // Writes row `next` of the noise EMD into out and advances; false when there is no such row.
  bool Next(Sifter& sifter, double* out);
  // The IMF number of the row the last successful Next wrote, 0 if it was the residue.
  int last_imf() const { return residue_given_ ? 0 : imfs_; }
  // The running residue: the realisation itself before the first Next.
  const Eigen::VectorXd& residue() const { return residue_; }

 private:
  Eigen::VectorXd residue_;
  double input_max_abs_;
  int imfs_ = 0;  // IMF rows written so far
  bool finished_ = false;
  bool residue_given_ = false;
};

// Refuses (OptionError naming ensemble_size) an ensemble whose white-noise state, this many
// N-vectors per realisation, would not fit in half the machine's memory, instead of dying of it.
void RequireNoiseStateFits(double ensemble, Eigen::Index n, double vectors_per_realisation);

// Sample standard deviation (N - 1), as MATLAB's std.
double SampleStd(const double* x, Eigen::Index n);

// A residue that varies by no more than the rounding of its magnitude (a large offset under a
// small oscillation, once the oscillation is out) holds nothing but rounding: each further IMF
// would be rounding too, and its extrema would never run out (EMD and ICEEMDAN ran without end on
// 1e12 + sin). True, with the report's stop reason set, for such a residue.
bool ResidueAtRounding(const Eigen::VectorXd& r, DecompositionReport& report);

// emd.m's main loop on r (in place): IMFs are appended until the residue has < 3 extrema, is
// negligible against r's initial amplitude or at its own rounding (ResidueAtRounding), the next
// IMF would not change it, or max_imfs (0 = no cap) IMFs are in `imfs`.
void EmdLoop(Sifter& sifter, Eigen::VectorXd& r, int max_imfs, std::vector<Eigen::VectorXd>& imfs,
             DecompositionReport& report);
Decomposition AssembleResult(std::vector<Eigen::VectorXd> imfs, Eigen::VectorXd residue,
                             DecompositionReport report);

Decomposition RunEmd(const Eigen::Ref<const Eigen::VectorXd>& x, const DecompositionOptions& o);
Decomposition RunEemd(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job);
Decomposition RunCeemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job);
Decomposition RunIceemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job);
Decomposition RunBeemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job);

// The energies of the realisations' white-noise modes so far: relative_log2[i][k - 1] =
// log2 ||E_k(w_i)||^2 - RobustLog2NoiseEnergy(E_1(w_i)) for every IMF row k of realisation i's
// EMD taken so far (a realisation whose EMD ended early has fewer entries). The record's own
// modes compare with them on the same terms, whatever N and the sifting options are.
struct NoiseEnergies {
  std::vector<std::vector<double>> relative_log2;
};

// What ends the noise assistance of the ICEEMDAN stages, asked before every stage k >= 1 with
// the modes so far (normalised input), the residue r, a free sifter and N-vector, and the noise
// modes' energies (empty unless asked for; then up to mode k + 1, the one stage k would use):
// true goes on with noise; false ends it, after the policy has set report.stop_reason and
// appended to modes (taking it from r) any mode it extracted to decide. Plain EMD then finishes
// the decomposition.
using NoiseStagePolicy = std::function<bool(
    int stage, std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& r, Sifter& sifter,
    Eigen::VectorXd& scratch, const NoiseEnergies& noise, DecompositionReport& report)>;
// ICEEMDAN's stages under a policy (empty: noise assistance to the end, ICEEMDAN itself).
// noise_energies: the policy reads them, so each stage takes its noise rows before asking (one
// more N-vector per realisation); the modes are the same bits either way.
Decomposition RunIceemdanStages(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job,
                                const NoiseStagePolicy& go_on, bool noise_energies = false);

}  // namespace gyrodrift::decomposition::internal
