// Plain EMD (Rilling & Flandrin's emd.m main loop) and the incremental noise EMD.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "decomposition/drivers.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace gyrodrift::decomposition::internal {

double SampleStd(const double* x, Eigen::Index n) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) sum += x[i];
  const double mean = sum / static_cast<double>(n);
  double ss = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) ss += (x[i] - mean) * (x[i] - mean);
  return std::sqrt(ss / static_cast<double>(n - 1));
}

namespace {
// Signals from this length on give back the sifter's node buffers after every IMF: the page
// faults of touching them again are then a small fraction of an IMF's sifting.
constexpr Eigen::Index kReleaseNodeBuffersSamples = Eigen::Index{1} << 20;
// Modes from this length on (1 MiB) are given back to the system one by one as they are
// assembled.
constexpr Eigen::Index kTrimSamples = Eigen::Index{1} << 17;

double MaxAbs(const double* x, Eigen::Index n) {
  double m = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) m = std::max(m, std::abs(x[i]));
  return m;
}
}  // namespace

NoiseModes::NoiseModes(Eigen::VectorXd noise)
    : residue_(std::move(noise)), input_max_abs_(MaxAbs(residue_.data(), residue_.size())) {}

bool NoiseModes::Next(Sifter& sifter, double* out) {
  const Eigen::Index n = residue_.size();
  if (!finished_) {
    // emd.m stops when the residue has < 3 extrema or is negligible against the input.
    if (MaxAbs(residue_.data(), n) < 1e-10 * input_max_abs_) {
      finished_ = true;
    } else {
      const SiftOutcome outcome = sifter.ExtractImf(residue_.data(), out);
      if (outcome.extracted) {
        for (Eigen::Index i = 0; i < n; ++i) residue_[i] = residue_[i] - out[i];
        ++imfs_;
        return true;
      }
      finished_ = true;
    }
  }
  if (residue_given_) return false;
  residue_given_ = true;
  if ((residue_.array() == 0.0).all()) return false;
  std::copy(residue_.data(), residue_.data() + n, out);
  return true;
}

bool ResidueAtRounding(const Eigen::VectorXd& r, DecompositionReport& report) {
  const double magnitude = MaxAbs(r.data(), r.size());
  if (!(r.maxCoeff() - r.minCoeff() <=
        1024.0 * std::numeric_limits<double>::epsilon() * magnitude)) {
    return false;
  }
  report.stop_reason = "residue varies by no more than the rounding of its magnitude";
  return true;
}

void EmdLoop(Sifter& sifter, Eigen::VectorXd& r, int max_imfs, std::vector<Eigen::VectorXd>& imfs,
             DecompositionReport& report) {
  const Eigen::Index n = r.size();
  const double reference = MaxAbs(r.data(), n);
  for (;;) {
    if (max_imfs > 0 && static_cast<int>(imfs.size()) >= max_imfs) {
      report.stop_reason = "IMF cap (" + std::to_string(max_imfs) + ") reached";
      return;
    }
    if (CountExtrema(r.data(), n).extrema() < 3) {
      report.stop_reason = "residue has fewer than 3 extrema";
      return;
    }
    if (MaxAbs(r.data(), n) < 1e-10 * reference) {
      report.stop_reason = "residue below 1e-10 of the input amplitude";
      return;
    }
    if (ResidueAtRounding(r, report)) return;
    Eigen::VectorXd imf(n);  // extracted where it is kept: no buffer and copy beside the modes
    const SiftOutcome outcome = sifter.ExtractImf(r.data(), imf.data());
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double next = r[i] - imf[i];
      changed |= next != r[i];
      r[i] = next;
    }
    if (!changed) {  // an IMF below the residue's rounding: the same residue again, without end
      report.stop_reason = "the next IMF is below the rounding of the residue";
      return;
    }
    imfs.push_back(std::move(imf));
    if (n >= kReleaseNodeBuffersSamples) sifter.ReleaseNodeBuffers();
    report.sifts_per_imf.push_back(outcome.sifts);
    report.sift_cap_hit.push_back(outcome.cap_hit);
    report.sift_cap_hits += outcome.cap_hit;
  }
}

Decomposition AssembleResult(std::vector<Eigen::VectorXd> imfs, Eigen::VectorXd residue,
                             DecompositionReport report) {
  Decomposition result;
  const Eigen::Index n = residue.size();
  result.imfs.resize(n, static_cast<Eigen::Index>(imfs.size()));
  assert(report.sifts_per_imf.size() == imfs.size() && report.sift_cap_hit.size() == imfs.size());
  for (size_t k = 0; k < imfs.size(); ++k) {
    assert(imfs[k].size() == n);
    result.imfs.col(static_cast<Eigen::Index>(k)) = imfs[k];
    Eigen::VectorXd().swap(imfs[k]);  // free as we go: the peak holds one copy of the modes
#ifdef __GLIBC__
    // glibc keeps a freed mode that sits inside its heap (modes below its mmap threshold, which
    // rises to 32 MiB as large blocks are freed): without this the copy doubled the modes' memory
    // at 1e6 samples.
    if (n >= kTrimSamples) malloc_trim(0);
#endif
  }
  result.residue = std::move(residue);
  result.report = std::move(report);
  return result;
}

Decomposition RunEmd(const Eigen::Ref<const Eigen::VectorXd>& x, const DecompositionOptions& o) {
  DecompositionReport report;
  report.method = Method::kEmd;
  Eigen::VectorXd r = x;
  std::vector<Eigen::VectorXd> imfs;
  {
    Sifter sifter(x.size(), o.sifting);  // its buffers are gone before the modes are assembled
    EmdLoop(sifter, r, o.max_imfs, imfs, report);
  }
  return AssembleResult(std::move(imfs), std::move(r), std::move(report));
}

}  // namespace gyrodrift::decomposition::internal
