// Seeded, reproducible random streams.
//
// There is no global generator. Every stochastic routine takes a seed, and work item i (ensemble
// member, Monte-Carlo run, named noise source) draws from its own stream derived from
// (seed, i), so results do not depend on how work is spread over threads.
// Generator: xoshiro256** (Blackman & Vigna 2018), state filled by SplitMix64 from (seed, stream).
// Normals: Box-Muller using both outputs, so a stream's normals are reproducible on every platform
// with an IEEE libm (std::normal_distribution is not specified across standard libraries).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string_view>

namespace gyrodrift {

class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream);

  std::uint64_t NextU64();
  // Uniform in [0, 1) with 53 random bits.
  double Uniform();
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Standard normal N(0, 1).
  double Normal();
  // Fills `out` with independent standard normals.
  void FillNormal(Eigen::Ref<Eigen::VectorXd> out);
  void FillNormal(double* out, Eigen::Index n);

 private:
  std::uint64_t s_[4];
  double spare_normal_ = 0.0;
  bool has_spare_ = false;
};

// FNV-1a 64 (Fowler, Noll & Vo) of the bytes of text: the project's one non-cryptographic hash
// (stream ids, model-file checksums, calibration fingerprints).
std::uint64_t Fnv1a64(std::string_view text);

// Stable 64-bit id of a named stream (FNV-1a of the name), for sources such as "arw" or "bias".
std::uint64_t StreamId(std::string_view name);

}  // namespace gyrodrift
