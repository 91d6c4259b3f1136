// What the per-method decomposition tests build their hand computations from: the drawn noise
// streams, MATLAB's sample standard deviation, and plain EMD's first IMF and local mean.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>

#include "decomposition/drivers.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::decomposition::hand_made {

// Stream (seed, i), as the noise-assisted methods draw realisation i.
inline Eigen::VectorXd Drawn(std::uint64_t seed, int i, Eigen::Index n) {
  Eigen::VectorXd w(n);
  Rng(seed, static_cast<std::uint64_t>(i)).FillNormal(w);
  return w;
}

// Streams (seed, 0..columns-1) as the columns of a supplied-noise matrix.
inline Eigen::MatrixXd DrawnColumns(std::uint64_t seed, int columns, Eigen::Index n) {
  Eigen::MatrixXd w(n, columns);
  for (int i = 0; i < columns; ++i) w.col(i) = Drawn(seed, i, n);
  return w;
}

// Sample standard deviation with N - 1, as the methods (and MATLAB's std) take it.
inline double Std(const Eigen::VectorXd& v) { return internal::SampleStd(v.data(), v.size()); }

// E_1(y): the first IMF of plain EMD.
inline Eigen::VectorXd FirstImf(const Eigen::VectorXd& y) {
  const Decomposition d = Emd(y, {}, 1);
  EXPECT_EQ(d.num_imfs(), 1);
  return d.imfs.col(0);
}

// M(y) = y - E_1(y), the local mean.
inline Eigen::VectorXd LocalMean(const Eigen::VectorXd& y) { return y - FirstImf(y); }

}  // namespace gyrodrift::decomposition::hand_made
