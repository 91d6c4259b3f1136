// EEMD (Wu & Huang 2009): the mean, mode by mode, of the EMDs of x + a w_i over I white-noise
// realisations, every member held to the same IMF count (log2 N - 1 unless max_imfs) so that
// modes align.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "decomposition/drivers.h"
#include "decomposition/noise_ensemble.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::decomposition::internal {

Decomposition RunEemd(const Eigen::Ref<const Eigen::VectorXd>& x, const Job& job) {
  const DecompositionOptions& o = job.options;
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(job);
  const int max_imfs =
      o.max_imfs > 0
          ? o.max_imfs
          : std::max(1, static_cast<int>(std::floor(std::log2(static_cast<double>(n)))) - 1);
  const double amplitude = o.noise_strength * SampleStd(x.data(), n);
  auto workers = MakeWorkers(ensemble, job, n);

  Eigen::MatrixXd mean_imfs = Eigen::MatrixXd::Zero(n, max_imfs);
  Eigen::VectorXd mean_residue = Eigen::VectorXd::Zero(n);
  std::vector<StageStats> stats(static_cast<size_t>(max_imfs));
  struct Member {
    std::vector<Eigen::VectorXd> imfs;
    Eigen::VectorXd residue;
    DecompositionReport report;
  };
  const double inv = 1.0 / ensemble;
  ParallelOrderedReduce(
      ensemble, job.threads(),
      [&](int i, int w) {
        Member m;
        m.residue = x + amplitude * DrawNoise(job, i, n);
        EmdLoop(workers[static_cast<size_t>(w)].sifter, m.residue, max_imfs, m.imfs, m.report);
        return m;
      },
      [&](int i, Member m) {
        job.context.execution.Report(static_cast<double>(i + 1) / ensemble, ToString(o.method));
        for (size_t k = 0; k < m.imfs.size(); ++k) {
          mean_imfs.col(static_cast<Eigen::Index>(k)) += m.imfs[k] * inv;
          SiftOutcome s;
          s.sifts = m.report.sifts_per_imf[k];
          s.cap_hit = m.report.sift_cap_hit[k];
          stats[k].Add(s);
        }
        mean_residue += m.residue * inv;
      });

  DecompositionReport report = EnsembleReport(Method::kEemd, job, workers);
  for (const auto& s : stats) s.Report(report);
  report.stop_reason =
      "fixed IMF count " + std::to_string(max_imfs) + " (EEMD aligns every member's modes)";
  Decomposition result;
  result.imfs = std::move(mean_imfs);
  result.residue = std::move(mean_residue);
  result.report = std::move(report);
  return result;
}

}  // namespace gyrodrift::decomposition::internal
