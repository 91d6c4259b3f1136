// CEEMDAN (Torres, Colominas, Schlotthauer & Flandrin 2011): stage k's mode is the ensemble mean
// of the first EMD mode of r_k + eps_k E_k(w_i), E_k the k-th EMD mode of realisation i, as the
// reference ceemdan.m computes it.
#include <optional>
#include <string>
#include <vector>

#include "decomposition/drivers.h"
#include "decomposition/noise_ensemble.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::decomposition::internal {

Decomposition RunCeemdan(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job) {
  const DecompositionOptions& o = job.options;
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(job);
  const double eps = o.noise_strength;
  const double sx = SampleStd(x.data(), n);
  const Eigen::VectorXd xn = x / sx;
  auto workers = MakeWorkers(ensemble, job, n);
  std::vector<std::optional<NoiseRows>> noise(static_cast<size_t>(ensemble));
  DecompositionReport report = EnsembleReport(Method::kCeemdan, job, workers);
  const double inv = 1.0 / ensemble;

  std::vector<Eigen::VectorXd> modes;
  Eigen::VectorXd r = xn;
  double reported = 0.0;  // progress shown so far
  for (int stage = 0;; ++stage) {
    if (StagesEnd(o, modes.size(), r, true, report)) break;
    const double sr = SampleStd(r.data(), n);
    Eigen::VectorXd mode = Eigen::VectorXd::Zero(n);
    StageStats stats;
    ParallelOrderedReduce(
        ensemble, job.threads(),
        [&](int i, int w) {
          Worker& wk = workers[static_cast<size_t>(w)];
          auto& modes_i = noise[static_cast<size_t>(i)];
          if (stage == 0) {
            // Stage 1 adds the realisation itself; its EMD then feeds the later stages.
            modes_i.emplace(job, i, n);
            wk.input = xn + eps * modes_i->white();
          } else if (NextNoiseRow(job, i, *modes_i, wk.sifter, wk.noise.data())) {
            // Torres et al. 2011, stage k: r_k + eps_k E_k(w); here eps_k keeps the added noise
            // at eps * std(r_k), a constant SNR per stage.
            const double sn = SampleStd(wk.noise.data(), n);
            for (Eigen::Index j = 0; j < n; ++j)
              wk.input[j] = r[j] + sr * (eps * (wk.noise[j] / sn));
          } else {
            wk.input = r;
          }
          StageTerm term;
          term.outcome = wk.sifter.ExtractImf(wk.input.data(), wk.imf.data());
          term.value = term.outcome.extracted ? wk.imf : Eigen::VectorXd::Zero(n);
          return term;
        },
        [&](int i, StageTerm term) {
          for (Eigen::Index j = 0; j < n; ++j) mode[j] = mode[j] + term.value[j] * inv;
          stats.Add(term.outcome);
          ReportProgress(job, stage, i, ensemble, n, reported);
        });
    stats.Report(report);
    r -= mode;
    modes.push_back(std::move(mode));
    ++report.noise_assisted_stages;
  }
  // The realisations' noise state (one N-vector each) is the bulk of the memory: free it first.
  std::vector<std::optional<NoiseRows>>().swap(noise);
  Scale(modes, r, sx);
  return AssembleResult(std::move(modes), std::move(r), std::move(report));
}

}  // namespace gyrodrift::decomposition::internal
