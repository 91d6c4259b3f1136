// Private: the five-term IEEE 952 model the noise fit works with (noise_fit.cc,
// noise_subset_fits.cc, noise_model_selection.cc). Term j = 0..4 is Q, N, B, K, R; a model is a
// bit mask of its terms; coefficients are the squared raw terms in deg/h and seconds.
#pragma once

#include <bit>
#include <numbers>
#include <vector>

#include "gyrodrift/allan/noise_fit.h"

namespace gyrodrift::allan::internal {

constexpr int kTerms = 5;  // Q, N, B, K, R
constexpr unsigned kAllTerms = (1u << kTerms) - 1;
inline const double kBiasFactor = 2.0 * std::numbers::ln2 / std::numbers::pi;  // (0.664)^2

// Model column of term j at tau (s).
inline double Column(int j, double tau) {
  switch (j) {
    case 0:
      return 3.0 / (tau * tau);
    case 1:
      return 1.0 / tau;
    case 2:
      return kBiasFactor;
    case 3:
      return tau / 3.0;
    default:
      return 0.5 * tau * tau;
  }
}

// Raw term (sqrt of the coefficient, deg/h-and-seconds units) -> reporting unit.
inline double ToReportUnit(int j, double raw) {
  switch (j) {
    case 0:  // deg/h * s -> deg -> urad
      return raw / 3600.0 * std::numbers::pi / 180.0 * 1e6;
    case 1:  // deg/h * sqrt(s) -> deg/sqrt(h)
      return raw / 60.0;
    case 2:
      return raw;
    case 3:  // deg/h / sqrt(s) -> deg/h/sqrt(h)
      return raw * 60.0;
    default:  // deg/h / s -> deg/h/h
      return raw * 3600.0;
  }
}

inline NoiseTerm* TermAt(NoiseTerms& t, int j) {
  switch (j) {
    case 0:
      return &t.q_urad;
    case 1:
      return &t.n_dpsh;
    case 2:
      return &t.b_dph;
    case 3:
      return &t.k_dphpsh;
    default:
      return &t.r_dphph;
  }
}
inline const NoiseTerm* TermAt(const NoiseTerms& t, int j) {
  return TermAt(const_cast<NoiseTerms&>(t), j);
}

// Number of terms of a model.
inline int Size(unsigned mask) { return std::popcount(mask); }

// The terms of a model, in index order.
inline std::vector<int> TermsOf(unsigned mask) {
  std::vector<int> terms;
  for (int j = 0; j < kTerms; ++j)
    if (mask & (1u << j)) terms.push_back(j);
  return terms;
}

}  // namespace gyrodrift::allan::internal
