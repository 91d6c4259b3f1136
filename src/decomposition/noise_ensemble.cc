#include "decomposition/noise_ensemble.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::decomposition::internal {

int EnsembleSize(const Job& job) {
  return job.noise ? static_cast<int>(job.noise->cols()) : job.options.ensemble_size;
}

Eigen::VectorXd DrawNoise(const Job& job, int i, Eigen::Index n) {
  if (job.noise) {
    assert(job.noise->rows() == n && i < job.noise->cols());
    return job.noise->col(i);
  }
  Eigen::VectorXd w(n);
  Rng rng(job.options.seed, static_cast<std::uint64_t>(i));
  rng.FillNormal(w);
  return w;
}

bool NextNoiseRow(const Job& job, int i, NoiseRows& modes, Sifter& sifter, double* out) {
  if (!modes.Next(sifter, out)) return false;
  const auto& observer = job.context.noise_imf_observer;
  if (observer && modes.last_imf() > 0) observer(i, modes.last_imf(), out);
  return true;
}

DecompositionReport EnsembleReport(Method method, const Job& job,
                                   const std::vector<Worker>& workers) {
  DecompositionReport report;
  report.method = method;
  report.threads = static_cast<int>(workers.size());
  report.ensemble_size = EnsembleSize(job);
  report.seed = job.options.seed;
  report.supplied_noise = job.noise != nullptr;
  return report;
}

bool StagesEnd(const DecompositionOptions& o, size_t modes, const Eigen::VectorXd& r,
               bool check_extrema, DecompositionReport& report) {
  if (o.max_imfs > 0 && static_cast<int>(modes) >= o.max_imfs) {
    report.stop_reason = "IMF cap (" + std::to_string(o.max_imfs) + ") reached";
    return true;
  }
  if (check_extrema && CountExtrema(r.data(), r.size()).extrema() < 3) {
    report.stop_reason = "residue has fewer than 3 extrema";
    return true;
  }
  return check_extrema && ResidueAtRounding(r, report);
}

std::vector<Worker> MakeWorkers(int ensemble, const Job& job, Eigen::Index n) {
  const int count = std::min(ResolveThreads(job.threads()), ensemble);
  std::vector<Worker> workers;
  workers.reserve(static_cast<size_t>(count));
  for (int w = 0; w < count; ++w) workers.emplace_back(n, job.options.sifting);
  return workers;
}

void Scale(std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& residue, double factor) {
  for (auto& m : modes) m *= factor;
  residue *= factor;
}

void ReportProgress(const Job& job, int stage, int realisation, int ensemble, Eigen::Index n,
                    double& reported) {
  const Execution& execution = job.context.execution;
  if (!execution.progress) return;
  const double expected =
      std::max<double>(stage + 2, std::floor(std::log2(static_cast<double>(n))) - 1);
  const double estimate =
      std::min(0.99, (stage + static_cast<double>(realisation + 1) / ensemble) / expected);
  reported = std::max(reported, estimate);
  execution.progress(reported, ToString(job.options.method));
}

}  // namespace gyrodrift::decomposition::internal

namespace gyrodrift::decomposition {

NoiseEmds::NoiseEmds(Eigen::Index length, const DecompositionOptions& options,
                     const Execution& execution)
    : length_(length), seed_(options.seed), sifting_(options.sifting) {
  options.Validate();
  execution.Validate();
  if (length < 4) {
    throw DataError("NoiseEmds length " + std::to_string(length) + ": must be >= 4 samples");
  }
  internal::RequireNoiseStateFits(options.ensemble_size, length, RowsPerRealisation(length));
  realisations_.resize(static_cast<size_t>(options.ensemble_size));
  std::vector<std::optional<internal::Sifter>> sifters(
      static_cast<size_t>(ResolveThreads(execution.threads)));
  const DecompositionContext drawn;  // white noise drawn from (seed, i), no observer
  const internal::Job job{options, drawn};
  ParallelFor(options.ensemble_size, execution.threads, [&](int i, int w) {
    auto& sifter = sifters[static_cast<size_t>(w)];
    if (!sifter) sifter.emplace(length, options.sifting);
    Realisation& r = realisations_[static_cast<size_t>(i)];
    r.white = internal::DrawNoise(job, i, length);
    internal::NoiseModes modes(r.white);
    Eigen::VectorXd row(length);
    while (modes.Next(*sifter, row.data())) {
      r.rows.push_back(row);
      if (modes.last_imf() > 0) r.imfs = modes.last_imf();
    }
  });
}

bool NoiseEmds::Matches(Eigen::Index n, const DecompositionOptions& o) const {
  return n == length_ && o.seed == seed_ && o.ensemble_size == ensemble_size() &&
         o.sifting == sifting_;
}

}  // namespace gyrodrift::decomposition
