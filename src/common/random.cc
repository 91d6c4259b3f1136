#include "gyrodrift/common/random.h"

#include <cmath>
#include <numbers>
#include <string>

namespace gyrodrift {
namespace {

std::uint64_t SplitMix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

inline std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

}  // namespace

Rng::Rng(std::uint64_t seed, std::uint64_t stream) {
  // Two SplitMix rounds separate (seed, stream) pairs that differ in either word.
  std::uint64_t mix = seed;
  std::uint64_t seed_hash = SplitMix64(mix);
  mix = seed_hash ^ (stream * 0xD1B54A32D192ED03ULL + 0x8CB92BA72F3D8DD7ULL);
  for (auto& word : s_) word = SplitMix64(mix);
}

std::uint64_t Rng::NextU64() {
  const std::uint64_t result = Rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = Rotl(s_[3], 45);
  return result;
}

double Rng::Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }

double Rng::Normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_normal_;
  }
  // u1 in (0, 1] so the logarithm is finite.
  const double u1 = 1.0 - Uniform();
  const double u2 = Uniform();
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  spare_normal_ = radius * std::sin(angle);
  has_spare_ = true;
  return radius * std::cos(angle);
}

void Rng::FillNormal(double* out, Eigen::Index n) {
  for (Eigen::Index i = 0; i < n; ++i) out[i] = Normal();
}

void Rng::FillNormal(Eigen::Ref<Eigen::VectorXd> out) {
  for (Eigen::Index i = 0; i < out.size(); ++i) out[i] = Normal();
}

std::uint64_t Fnv1a64(std::string_view text) {
  std::uint64_t hash = 0xCBF29CE484222325ULL;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 0x100000001B3ULL;
  }
  return hash;
}

std::uint64_t StreamId(std::string_view name) { return Fnv1a64(name); }

std::uint64_t SeedFor(std::uint64_t seed, std::string_view path) {
  return Rng(seed, StreamId(path)).NextU64();
}

std::uint64_t SeedFor(std::uint64_t seed, std::string_view path, std::uint64_t index) {
  std::string indexed(path);
  indexed += '/';
  indexed += std::to_string(index);
  return SeedFor(seed, indexed);
}

}  // namespace gyrodrift
