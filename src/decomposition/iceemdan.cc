// ICEEMDAN (Colominas, Schlotthauer & Torres 2014): stage k's mode is r_k minus the ensemble mean
// of the local means of r_k + beta_k E_k(w_i), E_k the k-th EMD mode of realisation i, as the
// reference iceemdan.m computes it. BEEMDAN (beemdan.cc) runs these stages under a policy that
// ends the noise assistance.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "decomposition/drivers.h"
#include "decomposition/noise_ensemble.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::decomposition::internal {

Decomposition RunIceemdanStages(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job,
                                const NoiseStagePolicy& go_on, bool noise_energies) {
  const DecompositionOptions& o = job.options;
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(job);
  const double eps = o.noise_strength;
  const bool constant_snr = o.noise_scaling == NoiseScaling::kConstantSnr;
  const double sx = SampleStd(x.data(), n);
  const Eigen::VectorXd xn = x / sx;
  auto workers = MakeWorkers(ensemble, job, n);
  std::vector<std::optional<NoiseRows>> noise(static_cast<size_t>(ensemble));
  DecompositionReport report = EnsembleReport(o.method, job, workers);
  const double nr = static_cast<double>(ensemble);

  // noise_energies: every realisation's next noise row is taken before the policy decides (the
  // stage then uses it), so the policy sees the energies of the mode it is about to test. Each
  // realisation writes its own slots: the same values for any thread count.
  NoiseEnergies energies;
  std::vector<double> noise_log2_e1;
  std::vector<Eigen::VectorXd> ahead;
  std::vector<char> ahead_has;
  if (noise_energies) {
    energies.relative_log2.resize(static_cast<size_t>(ensemble));
    noise_log2_e1.resize(static_cast<size_t>(ensemble));
    ahead.assign(static_cast<size_t>(ensemble), Eigen::VectorXd());
    ahead_has.assign(static_cast<size_t>(ensemble), 0);
  }
  // Records row stage+1 of realisation i, if it is IMF stage+1 (not the residue).
  auto record = [&](int i, int stage, const NoiseRows& rows, const Eigen::VectorXd& row) {
    if (rows.last_imf() != stage + 1) return;
    const size_t slot = static_cast<size_t>(i);
    if (stage == 0) noise_log2_e1[slot] = RobustLog2NoiseEnergy(row);
    energies.relative_log2[slot].push_back(std::log2(row.squaredNorm()) - noise_log2_e1[slot]);
  };

  std::vector<Eigen::VectorXd> modes;
  Eigen::VectorXd r = xn;
  double reported = 0.0;  // progress shown so far
  for (int stage = 0;; ++stage) {
    if (StagesEnd(o, modes.size(), r, stage > 0, report)) break;
    const bool fetched = stage > 0 && noise_energies;
    if (fetched) {
      ParallelFor(ensemble, job.threads(), [&](int i, int w) {
        const size_t slot = static_cast<size_t>(i);
        if (ahead[slot].size() != n) ahead[slot].resize(n);
        ahead_has[slot] = NextNoiseRow(job, i, *noise[slot], workers[static_cast<size_t>(w)].sifter,
                                       ahead[slot].data());
        if (ahead_has[slot]) record(i, stage, *noise[slot], ahead[slot]);
      });
    }
    if (stage > 0 && go_on &&
        !go_on(stage, modes, r, workers[0].sifter, workers[0].imf, energies, report)) {
      // The policy ended the noise assistance: plain EMD finishes the decomposition.
      const std::string reason = report.stop_reason;
      // EmdLoop's cap counts every mode in `modes`, the noise-assisted ones included: the
      // caller's max_imfs as it is (at or past it, EmdLoop only says so).
      EmdLoop(workers[0].sifter, r, o.max_imfs, modes, report);
      report.stop_reason = reason + "; then " + report.stop_reason;
      break;
    }

    const double sr = stage > 0 ? SampleStd(r.data(), n) : 0.0;
    Eigen::VectorXd next = Eigen::VectorXd::Zero(n);
    StageStats stats;
    ParallelOrderedReduce(
        ensemble, job.threads(),
        [&](int i, int w) {
          Worker& wk = workers[static_cast<size_t>(w)];
          auto& modes_i = noise[static_cast<size_t>(i)];
          if (stage == 0) modes_i.emplace(job, i, n);
          // Row stage+1 of the realisation's EMD (the residue row counts, as in ceemdan.m).
          bool has_noise;
          if (fetched) {
            has_noise = ahead_has[static_cast<size_t>(i)] != 0;
            if (has_noise) wk.noise = ahead[static_cast<size_t>(i)];
          } else {
            has_noise = NextNoiseRow(job, i, *modes_i, wk.sifter, wk.noise.data());
            if (noise_energies && has_noise) record(i, stage, *modes_i, wk.noise);
          }
          if (!has_noise) {
            // Fewer noise modes than stages: the local mean of r_k without noise. wk.noise is
            // then another realisation's row, not this one's. (Never at stage 0: every noise
            // realisation varies, Run refuses a constant one, so its EMD has a first row.)
            wk.input = r;
          } else if (stage == 0) {
            const double se = SampleStd(wk.noise.data(), n);
            for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = xn[j] + (eps * wk.noise[j]) / se;
          } else {
            if (constant_snr) {
              const double se = SampleStd(wk.noise.data(), n);
              for (Eigen::Index j = 0; j < n; ++j)
                wk.input[j] = r[j] + sr * (eps * (wk.noise[j] / se));
            } else {
              for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = r[j] + sr * (eps * wk.noise[j]);
            }
          }
          StageTerm term;
          term.outcome = wk.sifter.ExtractImf(wk.input.data(), wk.imf.data());
          // Local mean M(y) = y - E1(y). Without an IMF (< 3 extrema) ceemdan.m takes 0 at the
          // first stage and y itself later.
          if (term.outcome.extracted) {
            term.value = wk.input - wk.imf;
          } else if (stage == 0) {
            term.value = Eigen::VectorXd::Zero(n);
          } else {
            term.value = wk.input;
          }
          return term;
        },
        [&](int i, StageTerm term) {
          for (Eigen::Index j = 0; j < n; ++j) next[j] = next[j] + term.value[j] / nr;
          stats.Add(term.outcome);
          ReportProgress(job, stage, i, ensemble, n, reported);
        });
    stats.Report(report);
    Eigen::VectorXd mode = r - next;
    modes.push_back(std::move(mode));
    r = std::move(next);
    ++report.noise_assisted_stages;
  }
  // The realisations' noise state (one N-vector each) is the bulk of the memory: free it first.
  std::vector<std::optional<NoiseRows>>().swap(noise);
  Scale(modes, r, sx);
  return AssembleResult(std::move(modes), std::move(r), std::move(report));
}

Decomposition RunIceemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job) {
  return RunIceemdanStages(x, job, {});
}

}  // namespace gyrodrift::decomposition::internal
