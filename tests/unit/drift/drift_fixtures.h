// Shared by the drift model's unit tests: a small synthetic thermal log with its true drift, and
// drift options small enough for a unit test (10-member ensembles, a 20-realisation level).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::drift::fixtures {

// A small thermal log: temperature ramps, a drift that follows a lagged temperature and its rate,
// white noise on top.
struct Log {
  Eigen::VectorXd rate, temperature, drift;
};

inline Log MakeLog(Eigen::Index n, std::uint64_t seed) {
  Log log{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Rng rng(seed, 0);
  double lagged = 20.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / n;
    log.temperature[t] = 20.0 + 15.0 * std::sin(2 * std::numbers::pi * 1.5 * x);
    const double previous = lagged;
    lagged += (log.temperature[t] - lagged) / 120.0;
    log.drift[t] = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous);
    log.rate[t] = log.drift[t] + 0.02 * rng.Normal();
  }
  return log;
}

inline DriftOptions Fast(Mode mode, Method method) {
  DriftOptions o;
  o.mode = mode;
  o.method = method;
  o.decomposition.ensemble_size = 10;
  o.selection.monte_carlo.realisations = 20;
  return o;
}

}  // namespace gyrodrift::drift::fixtures
