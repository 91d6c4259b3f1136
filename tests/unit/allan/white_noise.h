// White noise for the Allan-variance unit tests: n samples of standard deviation sigma, drawn from
// stream (seed, 0).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "gyrodrift/common/random.h"

namespace gyrodrift::allan {

inline Eigen::VectorXd WhiteNoise(Eigen::Index n, double sigma, std::uint64_t seed) {
  Rng rng(seed, 0);
  Eigen::VectorXd v(n);
  rng.FillNormal(v);
  return v * sigma;
}

}  // namespace gyrodrift::allan
