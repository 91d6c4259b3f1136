// What a compensation did to a gyro's output: its mean (the bias a calibration mainly moves), its
// RMS about zero, its standard deviation and its slow variation, before and after. One home for
// the figures `gyrodrift compensate`, the fleet calibration and the Python package report, so a
// bias moved by a model is never hidden behind an unchanged standard deviation (issue 22: a
// calibration that moved the mean from +1,811 to -12,118 deg/h left the std at 1,086 -> 1,085).
//
// Slow variation [definition, docs/drift.md 1.5]: the RMS, about their mean, of the means of
// consecutive blocks of block_s seconds (a last partial block dropped): the drift a navigation
// filter integrates, with the white noise averaged out of it (its share falls as 1/sqrt(samples
// per block)). It is not measured (NaN) on a log shorter than two blocks. Units: those of the
// output (deg/h, deg/s or rad/s). Cost O(N).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace gyrodrift::drift {

// Block length of the slow variation `compensate` reports, s: 10 minutes, the block of the thermal
// model's cross-validated skill and drift band (thermal_model.h).
inline constexpr double kSlowVariationBlockS = 600.0;

// Means of consecutive blocks of `block` samples (>= 1); a last partial block is dropped unless it
// is the only one (then its mean, of x.size() < block samples).
Eigen::VectorXd BlockMeans(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block);

// One signal's figures, in its units.
struct SignalSummary {
  double mean = 0.0;
  double rms = 0.0;  // about zero: sqrt(mean^2 + std^2)
  double std = 0.0;  // about the mean (population)
  double slow = 0.0;  // slow variation (header comment); NaN for fewer than 2 blocks
  Eigen::Index blocks = 0;  // the blocks the slow variation is over
};

// Figures of x (finite where logged) with blocks of `block` samples (>= 1). `logged` (empty, or
// one flag per sample, false on a row made up across a gap: --gaps carry) keeps the figures to
// the logged samples; the blocks stay blocks of the time grid, each the mean of its logged
// samples, and a block with none is left out (until 2026-11-27 the blocks were counted in logged
// samples: with 5 s logged of every 300 s, a "600-s block" spanned 10 h).
SignalSummary Summarise(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block,
                        const std::vector<bool>& logged = {});

struct CompensationSummary {
  SignalSummary before, after;
  Eigen::Index samples = 0;
  double block_s = kSlowVariationBlockS;  // of the slow variation
  Eigen::Index block = 1;                 // samples per block: round(block_s rate_hz), >= 1
  Eigen::Index blocks = 0;                // the blocks of the slow variation (Summarise)
  // Several lines: a table of the four figures before and after, named by `target` and `unit`
  // ("" = none), each line ending in a newline; then a warning when the compensation raised the
  // slow variation by more than a quarter (docs/drift.md 1.5).
  std::string Table(const std::string& target, const std::string& unit) const;
};

// The figures of the output y and of compensated (same length, >= 1 sample, finite where
// logged), sampled at rate_hz, with the slow variation over blocks of block_s seconds, over the
// `logged` samples (Summarise). Throws DataError for empty or non-finite signals or unequal
// lengths, OptionError for rate_hz outside [1e-9, 1e6] Hz or block_s outside [1e-6, 1e9] s.
CompensationSummary SummariseCompensation(const Eigen::Ref<const Eigen::VectorXd>& y,
                                          const Eigen::Ref<const Eigen::VectorXd>& compensated,
                                          double rate_hz, double block_s = kSlowVariationBlockS,
                                          const std::vector<bool>& logged = {});

}  // namespace gyrodrift::drift
