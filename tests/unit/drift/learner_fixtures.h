// Shared by the learner unit tests (learner_test.cc and one learner_<kind>_test.cc per kind): a
// smooth 2-D regression problem with known truth, and exact comparison helpers.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/learner.h"

namespace gyrodrift::drift::fixtures {

struct Data {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;      // noisy
  Eigen::VectorXd truth;  // noise-free
};

// y = sin(x1) + 0.5 x2^2 + noise, x uniform on [-2, 2]^2.
inline Data SineBowl(int n, double noise_sd, std::uint64_t seed) {
  Rng rng(seed, 0);
  Data d;
  d.x.resize(n, 2);
  d.y.resize(n);
  d.truth.resize(n);
  for (int i = 0; i < n; ++i) {
    d.x(i, 0) = rng.Uniform(-2.0, 2.0);
    d.x(i, 1) = rng.Uniform(-2.0, 2.0);
    d.truth[i] = std::sin(d.x(i, 0)) + 0.5 * d.x(i, 1) * d.x(i, 1);
    d.y[i] = d.truth[i] + noise_sd * rng.Normal();
  }
  return d;
}

// The default options of a learner kind; polynomials of degree 3 (the default 2 cannot fit the
// bowl's sine).
inline LearnerOptions OptionsOf(LearnerKind kind) {
  LearnerOptions o;
  o.kind = kind;
  o.poly_degree = 3;
  return o;
}

inline double Rmse(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

inline bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

}  // namespace gyrodrift::drift::fixtures
