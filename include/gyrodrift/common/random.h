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

// The project's one seed rule. A call takes one seed from the user; the streams (seed, i), i =
// 0, 1, ..., are the decomposition's white-noise realisations (and the noise-level Monte-Carlo's,
// which reuses them); every other consumer draws from a seed derived by a named path: sub-model g
// of a drift model from SeedFor(seed, "sub-model", g), evaluation repeat r from SeedFor(seed,
// "repeat", r), the demo's run B from SeedFor(seed, "run-b"). Distinct paths give independent
// seeds for every seed, where offsets (seed + g, seed + r) made repeat r + 1's sub-model g - 1
// reuse repeat r's sub-model g, and sub-model 0's hidden units reuse the decomposition's noise.
// SeedFor(seed, path, index) is SeedFor(seed, path + "/" + decimal index).
std::uint64_t SeedFor(std::uint64_t seed, std::string_view path);
std::uint64_t SeedFor(std::uint64_t seed, std::string_view path, std::uint64_t index);

}  // namespace gyrodrift
