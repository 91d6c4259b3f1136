// Private: what the noise-assisted decompositions (eemd.cc, ceemdan.cc, iceemdan.cc,
// beemdan.cc) share: the white-noise realisations and their EMDs, per-thread workers, stage
// statistics and progress.
//
// Every method spreads realisations over worker threads with ParallelOrderedReduce: realisation i
// draws its white noise from Rng(seed, i) (or takes column i of the supplied matrix), and the
// ensemble averages are running sums of term / I accumulated in i order, as the reference
// ceemdan.m does, so the output is the same bits for any thread count.
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <optional>
#include <vector>

#include "decomposition/drivers.h"
#include "decomposition/sifting.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition::internal {

// I: the supplied noise's columns, or ensemble_size.
int EnsembleSize(const Job& job);

// White noise of realisation i, unit variance (before any method-specific scaling): the supplied
// noise's column i, or drawn from stream (seed, i).
Eigen::VectorXd DrawNoise(const Job& job, int i, Eigen::Index n);

// Realisation i's white noise and its EMD, row by row: read from the shared NoiseEmds when the
// context carries one, else drawn and sifted on demand.
class NoiseRows {
 public:
  NoiseRows(const Job& job, int i, Eigen::Index n) {
    if (job.context.noise_emds) {
      // Decompose checked the set against the options; supplied noise never shares one.
      assert(job.noise == nullptr && job.context.noise_emds->length() == n);
      cached_ = &job.context.noise_emds->realisation(i);
    } else {
      modes_.emplace(DrawNoise(job, i, n));
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
    assert(row.size() == cached_->white.size());
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
bool NextNoiseRow(const Job& job, int i, NoiseRows& modes, Sifter& sifter, double* out);

// Per-worker state: a sifter and scratch vectors sized once.
struct Worker {
  Worker(Eigen::Index n, const SiftingOptions& s) : sifter(n, s), noise(n), input(n), imf(n) {}
  Sifter sifter;
  Eigen::VectorXd noise, input, imf;
};

// A report of `method` with the ensemble's size, seed, whether its noise was supplied and the
// worker threads used.
DecompositionReport EnsembleReport(Method method, const Job& job,
                                   const std::vector<Worker>& workers);

// The stage-wise methods' end before a stage: the IMF cap reached, or (when check_extrema) a
// residue with fewer than 3 extrema. Sets report.stop_reason and returns true when it is the end.
bool StagesEnd(const DecompositionOptions& o, size_t modes, const Eigen::VectorXd& r,
               bool check_extrema, DecompositionReport& report);

// One worker per thread the ensemble can use.
std::vector<Worker> MakeWorkers(int ensemble, const Job& job, Eigen::Index n);

// Sift statistics of one stage across the realisations that sifted it (an EEMD member may end
// before the aligned mode count: it sifted nothing there, which is not a sift count of 0).
struct StageStats {
  long total_sifts = 0;
  int members = 0;
  bool cap_hit = false;
  int cap_hits = 0;
  void Add(const SiftOutcome& s) {
    total_sifts += s.sifts;
    ++members;
    cap_hit |= s.cap_hit;
    cap_hits += s.cap_hit;
  }
  void Report(DecompositionReport& report) const {
    report.sifts_per_imf.push_back(
        members == 0 ? 0
                     : static_cast<int>(std::lround(static_cast<double>(total_sifts) / members)));
    report.sift_cap_hit.push_back(cap_hit);
    report.sift_cap_hits += cap_hits;
  }
};

struct StageTerm {
  Eigen::VectorXd value;
  SiftOutcome outcome;
};

// Multiplies every mode and the residue by factor (undoing the input's normalisation).
void Scale(std::vector<Eigen::VectorXd>& modes, Eigen::VectorXd& residue, double factor);

// Stage-wise methods do not know their stage count in advance: EMD of noise gives about
// log2(N) modes, so that is the estimate (never reaching 1 before the end).
// `reported` keeps the display monotone when the estimate grows.
void ReportProgress(const Job& job, int stage, int realisation, int ensemble, Eigen::Index n,
                    double& reported);

}  // namespace gyrodrift::decomposition::internal
