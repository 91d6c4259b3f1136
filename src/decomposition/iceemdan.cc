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

namespace {

// The noise rows a stage takes before the policy decides (noise_energies): every realisation's
// next row is taken ahead (the stage then uses it), so the policy sees the energies of the mode it
// is about to test. Each realisation writes its own slots: the same values for any thread count.
// Sized 0 when the policy does not read the energies.
struct NoiseLookahead {
  explicit NoiseLookahead(int ensemble)
      : log2_e1(static_cast<size_t>(ensemble)),
        rows(static_cast<size_t>(ensemble)),
        has(static_cast<size_t>(ensemble), 0) {
    energies.relative_log2.resize(static_cast<size_t>(ensemble));
  }

  // Records row stage+1 of realisation i, if it is IMF stage+1 (not the residue).
  void Record(int i, int stage, const NoiseRows& modes, const Eigen::VectorXd& row) {
    if (modes.last_imf() != stage + 1) return;
    const size_t slot = static_cast<size_t>(i);
    if (stage == 0) log2_e1[slot] = RobustLog2NoiseEnergy(row);
    energies.relative_log2[slot].push_back(std::log2(row.squaredNorm()) - log2_e1[slot]);
  }

  // Takes every realisation's next row.
  void Fetch(const Job& job, int stage, Eigen::Index n,
             std::vector<std::optional<NoiseRows>>& noise, std::vector<Worker>& workers) {
    ParallelFor(static_cast<int>(rows.size()), job.threads(), [&](int i, int w) {
      const size_t slot = static_cast<size_t>(i);
      if (rows[slot].size() != n) rows[slot].resize(n);
      has[slot] = NextNoiseRow(job, i, *noise[slot], workers[static_cast<size_t>(w)].sifter,
                               rows[slot].data());
      if (has[slot]) Record(i, stage, *noise[slot], rows[slot]);
    });
  }

  NoiseEnergies energies;
  std::vector<double> log2_e1;  // log2 energy of each realisation's first noise IMF
  std::vector<Eigen::VectorXd> rows;
  std::vector<char> has;
};

// What every stage reads: the normalised input and the noise settings.
struct StageSettings {
  const Eigen::VectorXd& xn;  // the input over its sample standard deviation
  double eps;                 // noise strength
  bool constant_snr;          // NoiseScaling::kConstantSnr
};

// One realisation's term of a stage: the local mean M(y) = y - E1(y) of y = r_k plus its scaled
// noise row wk.noise (has_noise false: r_k alone); sr is std(r_k) (stage > 0).
StageTerm LocalMeanTerm(const StageSettings& s, int stage, const Eigen::VectorXd& r, double sr,
                        bool has_noise, Worker& wk) {
  const Eigen::Index n = r.size();
  const double eps = s.eps;
  if (!has_noise) {
    // Fewer noise modes than stages: the local mean of r_k without noise. wk.noise is then
    // another realisation's row, not this one's. (Never at stage 0: every noise realisation
    // varies, Run refuses a constant one, so its EMD has a first row.)
    wk.input = r;
  } else if (stage == 0) {
    const double se = SampleStd(wk.noise.data(), n);
    for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = s.xn[j] + (eps * wk.noise[j]) / se;
  } else if (s.constant_snr) {
    const double se = SampleStd(wk.noise.data(), n);
    for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = r[j] + sr * (eps * (wk.noise[j] / se));
  } else {
    for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = r[j] + sr * (eps * wk.noise[j]);
  }
  StageTerm term;
  term.outcome = wk.sifter.ExtractImf(wk.input.data(), wk.imf.data());
  // Without an IMF (< 3 extrema) ceemdan.m takes 0 at the first stage and y itself later.
  if (term.outcome.extracted) {
    term.value = wk.input - wk.imf;
  } else if (stage == 0) {
    term.value = Eigen::VectorXd::Zero(n);
  } else {
    term.value = wk.input;
  }
  return term;
}

}  // namespace

Decomposition RunIceemdanStages(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job,
                                const NoiseStagePolicy& go_on, bool noise_energies) {
  const DecompositionOptions& o = job.options;
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(job);
  const double sx = SampleStd(x.data(), n);
  const Eigen::VectorXd xn = x / sx;
  const StageSettings settings{xn, o.noise_strength, o.noise_scaling == NoiseScaling::kConstantSnr};
  auto workers = MakeWorkers(ensemble, job, n);
  std::vector<std::optional<NoiseRows>> noise(static_cast<size_t>(ensemble));
  DecompositionReport report = EnsembleReport(o.method, job, workers);
  const double nr = static_cast<double>(ensemble);
  NoiseLookahead lookahead(noise_energies ? ensemble : 0);

  std::vector<Eigen::VectorXd> modes;
  Eigen::VectorXd r = xn;
  double reported = 0.0;  // progress shown so far
  for (int stage = 0;; ++stage) {
    if (StagesEnd(o, modes.size(), r, stage > 0, report)) break;
    const bool fetched = stage > 0 && noise_energies;
    if (fetched) lookahead.Fetch(job, stage, n, noise, workers);
    if (stage > 0 && go_on &&
        !go_on(stage, modes, r, workers[0].sifter, workers[0].imf, lookahead.energies, report)) {
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
            has_noise = lookahead.has[static_cast<size_t>(i)] != 0;
            if (has_noise) wk.noise = lookahead.rows[static_cast<size_t>(i)];
          } else {
            has_noise = NextNoiseRow(job, i, *modes_i, wk.sifter, wk.noise.data());
            if (noise_energies && has_noise) lookahead.Record(i, stage, *modes_i, wk.noise);
          }
          return LocalMeanTerm(settings, stage, r, sr, has_noise, wk);
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
