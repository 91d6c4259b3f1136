// Private: the sifting engine shared by every method of the EMD family.
//
// Reproduces G. Rilling & P. Flandrin's emd.m (2007): extrema as sign changes of the first
// difference with plateaus mapped to their middle, nbsym = 2 mirrored extrema at each end with
// the fall-back when the mirrored nodes do not cover the end sample, not-a-knot cubic splines
// (MATLAB spline.m: slopes from a tridiagonal system solved in O(#nodes), a parabola through 3
// nodes, a line through 2), and the (0.05, 0.5, 0.05) stopping rule. Where emd.m raises an error
// inside the stopping test (too few extrema, a degenerate boundary), sifting stops with a zero
// mean, as emd.m's catch branch does.
// A Sifter owns every buffer it needs, sized once for N samples: extracting an IMF allocates
// nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "decomposition/spline.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition::internal {

struct ExtremaCounts {
  int minima = 0;
  int maxima = 0;
  int zero_crossings = 0;
  int extrema() const { return minima + maxima; }
};

// Counts extrema and zero crossings exactly as emd.m's extr() finds them.
ExtremaCounts CountExtrema(const double* x, Eigen::Index n);

struct SiftOutcome {
  int sifts = 0;          // number of h <- h - mean steps
  bool cap_hit = false;   // stopped by the sift cap, not by the rule
  bool extracted = true;  // false: the input had fewer than 3 extrema, no IMF exists
};

class Sifter {
 public:
  Sifter(Eigen::Index n, const SiftingOptions& options);

  // Extracts one IMF of x (length n) into imf. When x has fewer than 3 extrema no IMF exists:
  // returns extracted = false and leaves imf untouched.
  SiftOutcome ExtractImf(const double* x, double* imf);

  // Gives back the memory of the per-node buffers (spline arrays, extrema indices), sized for the
  // worst case and touched as far as the longest IMF so far reached: between IMFs of a long
  // signal, so that the first IMF's nodes (a third of the samples each envelope, for noise) are
  // not held through the rest of the decomposition. Results are unchanged.
  void ReleaseNodeBuffers();

  // Rilling's first-sift envelope nodes, for the unit tests: false if emd.m would fail.
  bool EnvelopeNodes(const double* x, std::vector<double>* tmin, std::vector<double>* zmin,
                     std::vector<double>* tmax, std::vector<double>* zmax);
  // Mean envelope and half-amplitude of x (what one sift subtracts); false as above.
  bool MeanAndAmplitude(const double* x, double* mean, double* amplitude);

 private:
  // Finds extrema indices (0-based) of h into indmin_/indmax_ and counts them; zero crossings
  // are counted only when asked (the Rilling rule needs them once per IMF, not per sift).
  ExtremaCounts FindExtrema(const double* h, bool count_zero_crossings);
  // Builds the mirrored node sets from indmin_/indmax_; false where emd.m raises an error.
  bool BoundaryConditions(const double* h);
  // Fits both envelope splines to the current node sets and evaluates them.
  void Envelopes();

  Eigen::Index n_;
  SiftingOptions options_;
  int max_sifts_;
  UninitialisedVector<int> indmin_, indmax_;
  int nmin_ = 0, nmax_ = 0;  // counts of the last FindExtrema
  EnvelopeSpline lower_, upper_;  // node sets (t, y) and fits of the two envelopes
  Eigen::VectorXd h_, next_, env_min_, env_max_;
};

}  // namespace gyrodrift::decomposition::internal
