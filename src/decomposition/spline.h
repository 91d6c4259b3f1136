// Private: not-a-knot cubic spline interpolation on the integer time grid t = 1..n, as MATLAB's
// spline.m / interp1(..., 'spline') computes it: a line through 2 nodes, the parabola through 3,
// and for 4 or more nodes the C2 piecewise cubic whose first and last two pieces are one cubic
// (slopes from a tridiagonal system solved in O(nodes)). Buffers are sized once; fitting and
// evaluating allocate nothing. Two splines (the lower and upper envelope) are fitted together,
// long systems in pieces, so that independent sequential sweeps overlap in the processor (the
// result is one plain sweep's, bit for bit); evaluation runs in the vector kernels of
// simd_kernels.h (SSE2 or AVX2, the same bits).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "decomposition/simd_kernels.h"

namespace gyrodrift::decomposition::internal {

// An allocator whose resize() leaves new elements uninitialised: the sifter's buffers are sized
// for the worst case (n nodes), and pages the signal never reaches are then never touched, so
// they cost no memory (a 1e7-sample decomposition would otherwise hold ~1.5 GB of zeros).
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using UninitialisedVector = std::vector<T, UninitialisedAllocator<T>>;

// Gives the whole pages inside [p, p + bytes) back to the system (Linux: madvise DONTNEED; they
// read as zeros when next touched and cost no memory until then; elsewhere nothing happens).
// For the worst-case buffers above once their contents are no longer needed: pages touched by a
// long first IMF would otherwise stay resident through all the later, shorter ones.
void ReleasePages(void* p, size_t bytes);

class EnvelopeSpline {
 public:
  // phase 0 or 1 staggers this spline's arrays against another one's in the cache (see the .cc).
  explicit EnvelopeSpline(Eigen::Index max_nodes, int phase = 0);
  EnvelopeSpline(const EnvelopeSpline&) = delete;  // the array pointers point into storage_
  EnvelopeSpline& operator=(const EnvelopeSpline&) = delete;
  EnvelopeSpline(EnvelopeSpline&&) = default;  // a moved vector keeps its buffer
  EnvelopeSpline& operator=(EnvelopeSpline&&) = default;
  // Node times must be integer-valued and strictly increasing, with t[0] <= 1 <= n <= t[m-1]
  // (the sifting's mirrored boundary nodes guarantee it).
  std::vector<double>& t() { return t_; }
  std::vector<double>& y() { return y_; }
  // Evaluates at t = 1..n into out, which must have room for n + kPadding values.
  void Evaluate(Eigen::Index n, double* out) const;
  // One sift's update with this spline as the upper envelope: next[i] = h[i] - (lower[i] + u(i))
  // / 2 for i < n, the same bits as Evaluate followed by that loop. lower, h and next must have
  // room for n + kPadding values (values past n are scratch).
  void EvaluateSift(Eigen::Index n, const double* lower, const double* h, double* next) const;
  static constexpr Eigen::Index kPadding = kSimdPadding;
  // Gives back the pages of the node arrays (ReleasePages); the next fit rewrites what it reads.
  void ReleaseStorage();

  friend void FitPair(EnvelopeSpline& a, EnvelopeSpline& b, size_t warm_up);

 private:
  void Prepare();
  SplineView view() const;
  std::vector<double> t_, y_;
  UninitialisedVector<double> storage_;                       // the per-node arrays below
  double *inv_dx_, *dd_, *slope_, *diag_, *rhs_, *c1_, *c2_;  // diag_: inverse pivots
};

// Rows each piece of a long sweep runs before its own (see the .cc).
inline constexpr size_t kSplineWarmUp = 48;
// The smallest system whose sweeps are cut into pieces, for a given warm-up.
size_t ChunkedSweepNodes(size_t warm_up);

// Solves the slopes of both splines. warm_up only changes the speed (tests use it to force the
// recomputation of pieces); the result is that of one plain sweep per spline, bit for bit.
void FitPair(EnvelopeSpline& a, EnvelopeSpline& b, size_t warm_up = kSplineWarmUp);

}  // namespace gyrodrift::decomposition::internal
