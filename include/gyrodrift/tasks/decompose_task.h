// The `decompose` user operation, written once for every front end (issue 25): the EMD family's
// settings by name as a user gives them, their one mapping onto
// decomposition::DecompositionOptions, the run (drawn or supplied noise) and the record the sidecar
// writes. `gyrodrift decompose` and the Python package's `decompose` call RunDecompose and nothing
// below it.
//
// Every default is the library's (a default-constructed DecompositionOptions), so it has one home.
// Cost: decomposition::Decompose's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "gyrodrift/decomposition/decomposition.h"

namespace gyrodrift::tasks {

namespace internal {
inline const decomposition::DecompositionOptions kDecompositionDefaults{};
}  // namespace internal

struct DecomposeSettings {
  using Defaults = decomposition::DecompositionOptions;
  // decomposition::Method name: emd|eemd|ceemdan|iceemdan|beemdan.
  std::string method{decomposition::ToString(internal::kDecompositionDefaults.method)};
  // decomposition::StopRule name: rilling|snumber|fixed|sd.
  std::string stop{decomposition::ToString(internal::kDecompositionDefaults.sifting.stop_rule)};
  int ensemble = internal::kDecompositionDefaults.ensemble_size;       // [1, 100000]
  double noise = internal::kDecompositionDefaults.noise_strength;      // eps
  std::uint64_t seed = internal::kDecompositionDefaults.seed;          // stream (seed, i)
  int threads = 0;                                                     // [0, 1024]; 0 = every core
  int max_imfs = internal::kDecompositionDefaults.max_imfs;            // 0 = until monotone
  int max_sifts = internal::kDecompositionDefaults.sifting.max_sifts;  // 0 = the rule's default
  int s_number = internal::kDecompositionDefaults.sifting.s_number;
  int fixed_sifts = internal::kDecompositionDefaults.sifting.fixed_sifts;
  double sd = internal::kDecompositionDefaults.sifting.sd_threshold;
  // decomposition::NoiseScaling name: colominas2014|constant-snr.
  std::string noise_scaling{
      decomposition::ToString(internal::kDecompositionDefaults.noise_scaling)};
  // decomposition::BeemdanBound name: ensemble|energy|stages|full.
  std::string bound{decomposition::ToString(internal::kDecompositionDefaults.beemdan_bound)};
  double band = internal::kDecompositionDefaults.band_confidence;  // 0.95 or 0.99
  int noise_stages = internal::kDecompositionDefaults.noise_stages;

  // The options of these settings, validated: OptionError naming the library's field
  // (ensemble_size, sifting.s_number, ...) or UsageError (an unknown name).
  decomposition::DecompositionOptions Options() const;
  // The context of `threads` (checked), reporting to `progress` (may be empty).
  decomposition::DecompositionContext Context(
      std::function<void(double, std::string_view)> progress = {}) const;
  void Validate() const;  // Options() and Context()
};

// UsageError unless the method takes supplied noise (every method but emd); `noise_name` names
// what supplied it ("noise_realisations", or a flag such as "--noise-file = n.csv").
void RequireNoiseTaken(const DecomposeSettings& settings, std::string_view noise_name);

// Beyond this many samples a decomposition does not fit in the memory of a workstation: the
// IMFs alone are 8 bytes x samples x (about log2(samples) modes), and sifting keeps a dozen
// working vectors of the signal's length per thread (measured peaks in docs/errors.md).
inline constexpr Eigen::Index kMaxDecomposeSamples = 20'000'000;

// DataError naming `signal_name` for an x shorter than dec::kMinDecomposeSamples or longer than
// kMaxDecomposeSamples, or constant (nothing to decompose). RunDecompose checks it; a front end may
// check it as soon as it has x.
void RequireDecomposable(const Eigen::VectorXd& x, std::string_view signal_name);

// The decomposition of x (RequireDecomposable); with `noise` not empty (one white-noise
// realisation per column; see RequireNoiseTaken) the supplied noise is used instead of drawing.
decomposition::Decomposition RunDecompose(
    const Eigen::VectorXd& x, const DecomposeSettings& settings, const Eigen::MatrixXd& noise = {},
    std::function<void(double, std::string_view)> progress = {},
    std::string_view noise_name = "noise_realisations", std::string_view signal_name = "x");

// The sidecar's records: the options the run used (ensemble_size the noise's columns when
// supplied; threads as asked) and the decomposition's report.
nlohmann::json DecomposeOptionsRecord(const DecomposeSettings& settings,
                                      Eigen::Index noise_columns);
nlohmann::json DecomposeReportRecord(const decomposition::Decomposition& d);

}  // namespace gyrodrift::tasks
