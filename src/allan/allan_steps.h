// Private: the steps Compute (allan.cc) and ComputeWithGaps (allan_gaps.cc) share.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "gyrodrift/allan/allan.h"

namespace gyrodrift::allan::internal {

// Angle (phase) samples the estimators work on, in rate unit x seconds, written into `x`
// (n + 1 points for rate data, n for angle data). `x` may be the samples' own storage (grown by
// one for rate data): every sample is read before its slot is written. The mean rate (or the
// straight line through the end angles) is removed first: every estimator here is blind to a
// constant rate, and without it the integrated angle of a biased gyro grows to values whose
// rounding would swamp the short-tau differences.
// `mean` is the samples' mean (rate data; unused for angle data).
void InternalPhase(const double* data, Eigen::Index n, double mean, const AllanOptions& o,
                   double* x);

// Points of the phase of n samples: n + 1 for rate data, n for angle data.
Eigen::Index PhaseLength(Eigen::Index n, const AllanOptions& o);

// Order of the estimator's differences of the phase: 3 for the Hadamard family, else 2.
int DifferenceOrder(Deviation d);

// The noise type that stands in where fewer than 30 points remain before any identification:
// the first identified one (the curve's noise type changes slowly with tau), else white rate.
int FirstIdentified(const std::vector<std::optional<int>>& alpha);

// Noise type, EDF and confidence bounds of p (p.m and p.dev set; NaN without intervals). `alpha`
// is the type identified at p's factor, if any; `carried` the last identified, updated here;
// `edf_phase_points` the phase length the EDF is computed for.
void SetInterval(const AllanOptions& options, const std::optional<int>& alpha,
                 Eigen::Index edf_phase_points, int& carried, AllanPoint& p);

}  // namespace gyrodrift::allan::internal
