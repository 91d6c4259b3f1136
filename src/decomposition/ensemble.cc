// The noise-assisted methods: EEMD, CEEMDAN, ICEEMDAN and BEEMDAN.
//
// Every method spreads realisations over worker threads with ParallelOrderedReduce: realisation i
// draws its white noise from Rng(seed, i) (or takes column i of the supplied matrix), and the
// ensemble averages are running sums of term / I accumulated in i order, as the reference
// ceemdan.m does, so the output is the same bits for any thread count.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "decomposition/internal.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::decomposition::internal {
namespace {

int EnsembleSize(const DecompositionOptions& o) {
  return o.supplied_noise ? static_cast<int>(o.supplied_noise->cols()) : o.ensemble_size;
}

// White noise of realisation i, unit variance (before any method-specific scaling).
Eigen::VectorXd DrawNoise(const DecompositionOptions& o, int i, Eigen::Index n) {
  if (o.supplied_noise) return o.supplied_noise->col(i);
  Eigen::VectorXd w(n);
  Rng rng(o.seed, static_cast<std::uint64_t>(i));
  rng.FillNormal(w);
  return w;
}

// Realisation i's white noise and its EMD, row by row: read from the shared NoiseEmds when the
// options carry one, else drawn and sifted on demand.
class NoiseRows {
 public:
  NoiseRows(const DecompositionOptions& o, int i, Eigen::Index n) {
    if (o.noise_emds) {
      cached_ = &o.noise_emds->realisation(i);
    } else {
      modes_.emplace(DrawNoise(o, i, n));
    }
  }
  // The realisation itself (valid before the first Next).
  const Eigen::VectorXd& white() const { return cached_ ? cached_->white : modes_->residue(); }
  // Writes the next row into out; false when there is none.
  bool Next(Sifter& sifter, double* out) {
    if (modes_) {
      if (!modes_->Next(sifter, out)) return false;
      last_imf_ = modes_->last_imf();
      return true;
    }
    if (next_ >= cached_->rows.size()) return false;
    const Eigen::VectorXd& row = cached_->rows[next_];
    std::copy(row.data(), row.data() + row.size(), out);
    ++next_;
    last_imf_ = static_cast<int>(next_) <= cached_->imfs ? static_cast<int>(next_) : 0;
    return true;
  }
  // The IMF number of the row the last successful Next wrote, 0 if it was the residue.
  int last_imf() const { return last_imf_; }

 private:
  std::optional<NoiseModes> modes_;
  const NoiseEmds::Realisation* cached_ = nullptr;
  size_t next_ = 0;
  int last_imf_ = 0;
};

// The next row of realisation i's noise EMD into out (false: none), shown to the observer when
// it is an IMF.
bool NextNoiseRow(const DecompositionOptions& o, int i, NoiseRows& modes, Sifter& sifter,
                  double* out) {
  if (!modes.Next(sifter, out)) return false;
  if (o.noise_imf_observer && modes.last_imf() > 0) o.noise_imf_observer(i, modes.last_imf(), out);
  return true;
}

// Per-worker state: a sifter and scratch vectors sized once.
struct Worker {
  Worker(Eigen::Index n, const SiftingOptions& s) : sifter(n, s), noise(n), input(n), imf(n) {}
  Sifter sifter;
  Eigen::VectorXd noise, input, imf;
};

std::vector<Worker> MakeWorkers(int ensemble, const DecompositionOptions& o, Eigen::Index n) {
  const int count = std::min(ResolveThreads(o.threads), ensemble);
  std::vector<Worker> workers;
  workers.reserve(static_cast<size_t>(count));
  for (int w = 0; w < count; ++w) workers.emplace_back(n, o.sifting);
  return workers;
}

// Sift statistics of one stage across realisations.
struct StageStats {
  long total_sifts = 0;
  bool cap_hit = false;
  int cap_hits = 0;
  void Add(const SiftOutcome& s) {
    total_sifts += s.sifts;
    cap_hit |= s.cap_hit;
    cap_hits += s.cap_hit;
  }
  void Report(DecompositionReport& report, int ensemble) const {
    report.sifts_per_imf.push_back(
        static_cast<int>(std::lround(static_cast<double>(total_sifts) / ensemble)));
    report.sift_cap_hit.push_back(cap_hit);
    report.sift_cap_hits += cap_hits;
  }
};

struct StageTerm {
  Eigen::VectorXd value;
  SiftOutcome outcome;
};

void Scale(std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& residue, double factor) {
  for (auto& m : modes) m *= factor;
  residue *= factor;
}

double Log2Energy(const Eigen::VectorXd& v) { return std::log2(v.squaredNorm()); }

// Stage-wise methods do not know their stage count in advance: EMD of noise gives about
// log2(N) modes, so that is the estimate (never reaching 1 before the end).
// `reported` keeps the display monotone when the estimate grows.
void ReportProgress(const DecompositionOptions& o, int stage, int realisation, int ensemble,
                    Eigen::Index n, double& reported) {
  if (!o.progress) return;
  const double expected =
      std::max<double>(stage + 2, std::floor(std::log2(static_cast<double>(n))) - 1);
  const double estimate =
      std::min(0.99, (stage + static_cast<double>(realisation + 1) / ensemble) / expected);
  reported = std::max(reported, estimate);
  o.progress(reported);
}

}  // namespace

Decomposition RunEemd(const Eigen::Ref<const Eigen::VectorXd>& x, const DecompositionOptions& o) {
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(o);
  const int max_imfs =
      o.max_imfs > 0
          ? o.max_imfs
          : std::max(1, static_cast<int>(std::floor(std::log2(static_cast<double>(n)))) - 1);
  const double amplitude = o.noise_strength * SampleStd(x.data(), n);
  auto workers = MakeWorkers(ensemble, o, n);

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
      ensemble, o.threads,
      [&](int i, int w) {
        Member m;
        m.residue = x + amplitude * DrawNoise(o, i, n);
        EmdLoop(workers[static_cast<size_t>(w)].sifter, m.residue, max_imfs, m.imfs, m.report);
        return m;
      },
      [&](int i, Member m) {
        if (o.progress) o.progress(static_cast<double>(i + 1) / ensemble);
        for (size_t k = 0; k < m.imfs.size(); ++k) {
          mean_imfs.col(static_cast<Eigen::Index>(k)) += m.imfs[k] * inv;
          SiftOutcome s;
          s.sifts = m.report.sifts_per_imf[k];
          s.cap_hit = m.report.sift_cap_hit[k];
          stats[k].Add(s);
        }
        mean_residue += m.residue * inv;
      });

  DecompositionReport report;
  report.method = Method::kEemd;
  report.ensemble_size = ensemble;
  report.seed = o.seed;
  report.supplied_noise = static_cast<bool>(o.supplied_noise);
  for (const auto& s : stats) s.Report(report, ensemble);
  report.stop_reason =
      "fixed IMF count " + std::to_string(max_imfs) + " (EEMD aligns every member's modes)";
  Decomposition result;
  result.imfs = std::move(mean_imfs);
  result.residue = std::move(mean_residue);
  result.report = std::move(report);
  return result;
}

Decomposition RunCeemdan(const Eigen::Ref<const Eigen::VectorXd>& x,
                         const DecompositionOptions& o) {
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(o);
  const double eps = o.noise_strength;
  const double sx = SampleStd(x.data(), n);
  const Eigen::VectorXd xn = x / sx;
  auto workers = MakeWorkers(ensemble, o, n);
  std::vector<std::optional<NoiseRows>> noise(static_cast<size_t>(ensemble));
  DecompositionReport report;
  report.method = Method::kCeemdan;
  report.ensemble_size = ensemble;
  report.seed = o.seed;
  report.supplied_noise = static_cast<bool>(o.supplied_noise);
  const double inv = 1.0 / ensemble;

  std::vector<Eigen::VectorXd> modes;
  Eigen::VectorXd r = xn;
  double reported = 0.0;  // progress shown so far
  for (int stage = 0;; ++stage) {
    if (o.max_imfs > 0 && static_cast<int>(modes.size()) >= o.max_imfs) {
      report.stop_reason = "IMF cap (" + std::to_string(o.max_imfs) + ") reached";
      break;
    }
    if (CountExtrema(r.data(), n).extrema() < 3) {
      report.stop_reason = "residue has fewer than 3 extrema";
      break;
    }
    const double sr = SampleStd(r.data(), n);
    Eigen::VectorXd mode = Eigen::VectorXd::Zero(n);
    StageStats stats;
    ParallelOrderedReduce(
        ensemble, o.threads,
        [&](int i, int w) {
          Worker& wk = workers[static_cast<size_t>(w)];
          auto& modes_i = noise[static_cast<size_t>(i)];
          if (stage == 0) {
            // Stage 1 adds the realisation itself; its EMD then feeds the later stages.
            modes_i.emplace(o, i, n);
            wk.input = xn + eps * modes_i->white();
          } else if (NextNoiseRow(o, i, *modes_i, wk.sifter, wk.noise.data())) {
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
          ReportProgress(o, stage, i, ensemble, n, reported);
        });
    stats.Report(report, ensemble);
    r -= mode;
    modes.push_back(std::move(mode));
    ++report.noise_assisted_stages;
  }
  // The realisations' noise state (one N-vector each) is the bulk of the memory: free it first.
  std::vector<std::optional<NoiseRows>>().swap(noise);
  Scale(modes, r, sx);
  return AssembleResult(std::move(modes), std::move(r), std::move(report));
}

Decomposition RunIceemdan(const Eigen::Ref<const Eigen::VectorXd>& x,
                          const DecompositionOptions& o) {
  const Eigen::Index n = x.size();
  const int ensemble = EnsembleSize(o);
  const double eps = o.noise_strength;
  const bool bounded = o.method == Method::kBeemdan && o.beemdan_bound != BeemdanBound::kFull;
  const bool constant_snr = o.noise_scaling == NoiseScaling::kConstantSnr;
  const double sx = SampleStd(x.data(), n);
  const Eigen::VectorXd xn = x / sx;
  auto workers = MakeWorkers(ensemble, o, n);
  std::vector<std::optional<NoiseRows>> noise(static_cast<size_t>(ensemble));
  DecompositionReport report;
  report.method = o.method;
  report.ensemble_size = ensemble;
  report.seed = o.seed;
  report.supplied_noise = static_cast<bool>(o.supplied_noise);
  const double nr = static_cast<double>(ensemble);

  // Flandrin, Goncalves & Rilling (2004): white-noise IMF energies and their confidence band.
  const double band_a = o.band_confidence >= 0.99 ? 0.46 : 0.474;
  const double band_b = o.band_confidence >= 0.99 ? -1.919 : -2.449;
  double log2_e1 = 0.0;  // log2 of the robust mode-1 noise energy estimate

  std::vector<Eigen::VectorXd> modes;
  Eigen::VectorXd r = xn;
  double reported = 0.0;  // progress shown so far
  bool plain_rest = false;
  for (int stage = 0;; ++stage) {
    if (o.max_imfs > 0 && static_cast<int>(modes.size()) >= o.max_imfs) {
      report.stop_reason = "IMF cap (" + std::to_string(o.max_imfs) + ") reached";
      break;
    }
    if (stage > 0 && CountExtrema(r.data(), n).extrema() < 3) {
      report.stop_reason = "residue has fewer than 3 extrema";
      break;
    }
    if (stage > 0 && bounded) {
      if (o.beemdan_bound == BeemdanBound::kFixedStages && stage >= o.noise_stages) {
        report.stop_reason = "noise assistance ended after the requested " +
                             std::to_string(o.noise_stages) + " stages; plain EMD for the rest";
        plain_rest = true;
      } else if (o.beemdan_bound == BeemdanBound::kEnergyBand) {
        // Probe: the plain EMD mode of r_k. Outside the noise band it is the first signal mode,
        // kept as the first IMF of the plain EMD that finishes the decomposition.
        Worker& wk = workers[0];
        const SiftOutcome probe = wk.sifter.ExtractImf(r.data(), wk.imf.data());
        const int k = stage + 1;  // mode number under test
        const double log2_energy = Log2Energy(wk.imf);
        const double log2_model = log2_e1 - std::log2(0.719) - k * std::log2(2.01);
        const double upper = log2_model + std::exp2(band_a * k + band_b);
        report.mode_log2_energy.push_back(log2_energy);
        report.noise_band_log2_upper.push_back(upper);
        if (log2_energy > upper) {
          char text[160];
          std::snprintf(text, sizeof(text),
                        "mode %d energy 2^%.2f above the %g%% white-noise band (2^%.2f); plain "
                        "EMD for the rest",
                        k, log2_energy, 100 * o.band_confidence, upper);
          report.stop_reason = text;
          plain_rest = true;
          r -= wk.imf;
          modes.push_back(wk.imf);
          report.sifts_per_imf.push_back(probe.sifts);
          report.sift_cap_hit.push_back(probe.cap_hit);
          report.sift_cap_hits += probe.cap_hit;
        }
      }
      if (plain_rest) {
        const std::string reason = report.stop_reason;
        const int remaining =
            o.max_imfs > 0 ? std::max(0, o.max_imfs - static_cast<int>(modes.size())) : 0;
        if (o.max_imfs == 0 || remaining > 0) {
          EmdLoop(workers[0].sifter, r, o.max_imfs > 0 ? remaining : 0, modes, report);
        }
        report.stop_reason = reason + "; then " + report.stop_reason;
        break;
      }
    }

    const double sr = stage > 0 ? SampleStd(r.data(), n) : 0.0;
    Eigen::VectorXd next = Eigen::VectorXd::Zero(n);
    StageStats stats;
    ParallelOrderedReduce(
        ensemble, o.threads,
        [&](int i, int w) {
          Worker& wk = workers[static_cast<size_t>(w)];
          auto& modes_i = noise[static_cast<size_t>(i)];
          if (stage == 0) modes_i.emplace(o, i, n);
          // Row stage+1 of the realisation's EMD (the residue row counts, as in ceemdan.m).
          const bool has_noise = NextNoiseRow(o, i, *modes_i, wk.sifter, wk.noise.data());
          if (stage == 0) {
            const double se = SampleStd(wk.noise.data(), n);
            for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = xn[j] + (eps * wk.noise[j]) / se;
          } else if (has_noise) {
            if (constant_snr) {
              const double se = SampleStd(wk.noise.data(), n);
              for (Eigen::Index j = 0; j < n; ++j)
                wk.input[j] = r[j] + sr * (eps * (wk.noise[j] / se));
            } else {
              for (Eigen::Index j = 0; j < n; ++j) wk.input[j] = r[j] + sr * (eps * wk.noise[j]);
            }
          } else {
            wk.input = r;  // fewer noise modes than stages: the local mean of r_k without noise
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
          ReportProgress(o, stage, i, ensemble, n, reported);
        });
    stats.Report(report, ensemble);
    Eigen::VectorXd mode = r - next;
    if (stage == 0) {
      // Robust energy of the noise in mode 1: N * (median|d_1| / 0.6745)^2.
      Eigen::VectorXd magnitude = mode.cwiseAbs();
      auto mid = magnitude.data() + n / 2;
      std::nth_element(magnitude.data(), mid, magnitude.data() + n);
      double median = *mid;
      if (n % 2 == 0) median = 0.5 * (median + *std::max_element(magnitude.data(), mid));
      log2_e1 = std::log2(static_cast<double>(n)) + 2.0 * std::log2(median / 0.6745);
    }
    modes.push_back(std::move(mode));
    r = std::move(next);
    ++report.noise_assisted_stages;
  }
  // The realisations' noise state (one N-vector each) is the bulk of the memory: free it first.
  std::vector<std::optional<NoiseRows>>().swap(noise);
  Scale(modes, r, sx);
  return AssembleResult(std::move(modes), std::move(r), std::move(report));
}

}  // namespace gyrodrift::decomposition::internal

namespace gyrodrift::decomposition {

NoiseEmds::NoiseEmds(Eigen::Index length, const DecompositionOptions& options)
    : length_(length), seed_(options.seed), sifting_(options.sifting) {
  options.Validate();
  if (options.supplied_noise) {
    throw UsageError(
        "NoiseEmds draws its own white noise: compute the EMDs of supplied noise "
        "by decomposing with it");
  }
  if (length < 4) {
    throw DataError("NoiseEmds length " + std::to_string(length) + ": must be >= 4 samples");
  }
  internal::RequireNoiseStateFits(options.ensemble_size, length, RowsPerRealisation(length));
  realisations_.resize(static_cast<size_t>(options.ensemble_size));
  std::vector<std::optional<internal::Sifter>> sifters(
      static_cast<size_t>(ResolveThreads(options.threads)));
  ParallelFor(options.ensemble_size, options.threads, [&](int i, int w) {
    auto& sifter = sifters[static_cast<size_t>(w)];
    if (!sifter) sifter.emplace(length, options.sifting);
    Realisation& r = realisations_[static_cast<size_t>(i)];
    r.white = internal::DrawNoise(options, i, length);
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
         o.sifting == sifting_ && !o.supplied_noise;
}

}  // namespace gyrodrift::decomposition
