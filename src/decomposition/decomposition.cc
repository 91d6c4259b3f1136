#include "gyrodrift/decomposition/decomposition.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

#include "common/enum_names.h"
#include "decomposition/drivers.h"
#include "decomposition/noise_ensemble.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/decomposition/energy_band.h"

namespace gyrodrift::decomposition {
namespace {

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;

constexpr std::array<std::pair<Method, std::string_view>, 5> kMethods{{
    {Method::kEmd, "emd"},
    {Method::kEemd, "eemd"},
    {Method::kCeemdan, "ceemdan"},
    {Method::kIceemdan, "iceemdan"},
    {Method::kBeemdan, "beemdan"},
}};
constexpr std::array<std::pair<StopRule, std::string_view>, 4> kStopRules{{
    {StopRule::kRilling, "rilling"},
    {StopRule::kSNumber, "snumber"},
    {StopRule::kFixed, "fixed"},
    {StopRule::kCauchySd, "sd"},
}};
constexpr std::array<std::pair<BeemdanBound, std::string_view>, 4> kBounds{{
    {BeemdanBound::kEnergyBand, "energy"},
    {BeemdanBound::kFixedStages, "stages"},
    {BeemdanBound::kFull, "full"},
    {BeemdanBound::kEnsembleBand, "ensemble"},
}};
constexpr std::array<std::pair<NoiseScaling, std::string_view>, 2> kScalings{{
    {NoiseScaling::kColominas2014, "colominas2014"},
    {NoiseScaling::kConstantSnr, "constant-snr"},
}};

}  // namespace

std::string_view ToString(Method method) { return EnumName(method, kMethods); }
bool UsesNoiseEmds(Method method) {
  return method == Method::kCeemdan || method == Method::kIceemdan || method == Method::kBeemdan;
}
Method MethodFromString(std::string_view name) {
  return EnumFromName(name, "method", kMethods);
}
std::string_view ToString(StopRule rule) { return EnumName(rule, kStopRules); }
StopRule StopRuleFromString(std::string_view name) {
  return EnumFromName(name, "stop_rule", kStopRules);
}
std::string_view ToString(BeemdanBound bound) { return EnumName(bound, kBounds); }
BeemdanBound BeemdanBoundFromString(std::string_view name) {
  return EnumFromName(name, "beemdan_bound", kBounds);
}
std::string_view ToString(NoiseScaling scaling) { return EnumName(scaling, kScalings); }
NoiseScaling NoiseScalingFromString(std::string_view name) {
  return EnumFromName(name, "noise_scaling", kScalings);
}

int SiftingOptions::EffectiveMaxSifts() const {
  if (max_sifts > 0) return max_sifts;
  switch (stop_rule) {
    case StopRule::kSNumber:
      return 50;
    case StopRule::kFixed:
      return fixed_sifts;
    case StopRule::kRilling:
    case StopRule::kCauchySd:
      return 2000;
  }
  return 2000;
}

void SiftingOptions::Validate() const {
  if (!(rilling_threshold1 > 0 && rilling_threshold1 < 1)) {
    ThrowOption("rilling_threshold1", FormatValue(rilling_threshold1), "in (0, 1)");
  }
  if (!(rilling_threshold2 >= rilling_threshold1) || !std::isfinite(rilling_threshold2)) {
    ThrowOption("rilling_threshold2", FormatValue(rilling_threshold2),
                "finite and >= rilling_threshold1 (" + FormatValue(rilling_threshold1) + ")");
  }
  if (!(rilling_tolerance >= 0 && rilling_tolerance < 1)) {
    ThrowOption("rilling_tolerance", FormatValue(rilling_tolerance), "in [0, 1)");
  }
  if (s_number < 1 || s_number > 1000) {
    ThrowOption("s_number", std::to_string(s_number), "an integer in [1, 1000]");
  }
  if (fixed_sifts < 1 || fixed_sifts > 100000) {
    ThrowOption("fixed_sifts", std::to_string(fixed_sifts), "an integer in [1, 100000]");
  }
  RequirePositive("sd_threshold", sd_threshold);
  if (max_sifts < 0 || max_sifts > 1000000) {
    ThrowOption("max_sifts", std::to_string(max_sifts),
                "an integer in [1, 1000000], or 0 for the stop rule's default cap");
  }
}

void DecompositionOptions::Validate() const {
  ValidateNested("sifting", [&] { sifting.Validate(); });
  if (max_imfs < 0 || max_imfs > 1000) {
    ThrowOption("max_imfs", std::to_string(max_imfs), "an integer in [0, 1000] (0 = no cap)");
  }
  // Every field is checked whatever the method, so a mistyped option is never silently ignored.
  if (ensemble_size < 1 || ensemble_size > 100000) {
    ThrowOption("ensemble_size", std::to_string(ensemble_size), "an integer in [1, 100000]");
  }
  if (!(noise_strength > 0 && noise_strength <= 10)) {
    ThrowOption("noise_strength", FormatValue(noise_strength), "in (0, 10]");
  }
  ValidateBandConfidence(band_confidence);
  if (noise_stages < 1 || noise_stages > 1000) {
    ThrowOption("noise_stages", std::to_string(noise_stages), "an integer in [1, 1000]");
  }
}

std::string DecompositionReport::Summary() const {
  std::string s = std::string(ToString(method)) + ": " + std::to_string(sifts_per_imf.size()) +
                  " IMFs, sifts per IMF [";
  for (size_t k = 0; k < sifts_per_imf.size(); ++k) {
    s += (k ? " " : "") + std::to_string(sifts_per_imf[k]);
  }
  s += "]";
  if (sift_cap_hits > 0) s += ", sift cap hit " + std::to_string(sift_cap_hits) + " times";
  if (ensemble_size > 0) {
    s += ", ensemble " + std::to_string(ensemble_size) +
         (supplied_noise ? " (supplied noise)" : ", seed " + std::to_string(seed));
  }
  if (UsesNoiseEmds(method)) {
    s += ", " + std::to_string(noise_assisted_stages) + " noise-assisted stages";
  }
  if (!stop_reason.empty()) s += "; stop: " + stop_reason;
  return s;
}

namespace internal {

void RequireNoiseStateFits(double ensemble, Eigen::Index n, double vectors_per_realisation) {
  const double state_bytes =
      ensemble * vectors_per_realisation * static_cast<double>(n) * sizeof(double);
  const double memory_bytes =
      static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
  if (memory_bytes > 0 && state_bytes > 0.5 * memory_bytes) {
    char rule[160];
    std::snprintf(rule, sizeof rule,
                  "small enough that its noise state (%.3g GB for %lld samples) fits in half "
                  "the memory (%.3g GB)",
                  state_bytes / 1e9, static_cast<long long>(n), memory_bytes / 1e9);
    ThrowOption("ensemble_size", std::to_string(static_cast<long long>(ensemble)), rule);
  }
}

}  // namespace internal

namespace {

// Decompose and DecomposeWithNoise: checks the inputs against each other, then runs the method.
Decomposition Run(const Eigen::Ref<const Eigen::VectorXd>& x, const internal::Job& job) {
  const DecompositionOptions& options = job.options;
  const DecompositionContext& context = job.context;
  options.Validate();
  context.execution.Validate();
  RequireFiniteSignal("input signal", x, kMinDecomposeSamples);
  const Eigen::Index n = x.size();
  if (job.noise) {
    const auto& w = *job.noise;
    if (options.method == Method::kEmd) {
      throw UsageError("supplied noise: method emd adds no noise (decompose with Decompose)");
    }
    if (w.rows() != n || w.cols() < 1) {
      throw DataError("supplied noise is " + std::to_string(w.rows()) + " x " +
                      std::to_string(w.cols()) + ": it must have one row per sample (" +
                      std::to_string(n) + ") and at least one realisation column");
    }
    for (Eigen::Index j = 0; j < w.cols(); ++j) {
      RequireFiniteSignal("supplied noise column " + std::to_string(j + 1), w.col(j), 1);
    }
    for (Eigen::Index j = 0; UsesNoiseEmds(options.method) && j < w.cols(); ++j) {
      // The CEEMDAN family scales each realisation's EMD modes to unit variance: a constant one
      // has no spread, and its stages would divide by a standard deviation of rounding error
      // and never end. (EEMD adds the noise as given: a constant column only shifts x.)
      const double spread = w.col(j).maxCoeff() - w.col(j).minCoeff();
      if (!(spread > 1e-9 * w.col(j).cwiseAbs().maxCoeff())) {
        throw DataError("supplied noise column " + std::to_string(j + 1) +
                        " is constant: a noise realisation must vary");
      }
    }
  }
  const bool ceemdan_family = UsesNoiseEmds(options.method);
  if (context.noise_emds &&
      !(ceemdan_family && !job.noise && context.noise_emds->Matches(n, options))) {
    throw UsageError("noise_emds (" + std::to_string(context.noise_emds->length()) +
                     " samples, ensemble " + std::to_string(context.noise_emds->ensemble_size()) +
                     ") do not match this decomposition (" + std::string(ToString(options.method)) +
                     ", " + std::to_string(n) +
                     " samples): they serve the CEEMDAN family with the same length, seed, "
                     "ensemble size and sifting, without supplied noise");
  }
  if (ceemdan_family) {
    // Each realisation keeps the running residue of its noise EMD (N doubles), and under
    // BEEMDAN's ensemble band its next row too.
    const bool ahead =
        options.method == Method::kBeemdan && options.beemdan_bound == BeemdanBound::kEnsembleBand;
    internal::RequireNoiseStateFits(internal::EnsembleSize(job), n, ahead ? 2.0 : 1.0);
  }
  // A signal with fewer than 3 extrema (constant, linear, monotone) has no IMF by definition.
  if (internal::CountExtrema(x.data(), n).extrema() < 3) {
    Decomposition result;
    result.imfs.resize(n, 0);
    result.residue = x;
    result.report.method = options.method;
    result.report.seed = options.seed;
    result.report.stop_reason = "input has fewer than 3 extrema: no IMF";
    return result;
  }
  if (options.method == Method::kEmd) return internal::RunEmd(x, options);
  Decomposition result = options.method == Method::kEemd       ? internal::RunEemd(x, job)
                         : options.method == Method::kCeemdan  ? internal::RunCeemdan(x, job)
                         : options.method == Method::kIceemdan ? internal::RunIceemdan(x, job)
                                                               : internal::RunBeemdan(x, job);
  // The stages' reports estimate the share done from a guess at the number of stages, so stop
  // short of it; the end is said once it is reached.
  job.context.execution.Report(1.0, ToString(options.method));
  return result;
}

}  // namespace

Decomposition Decompose(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const DecompositionOptions& options, const DecompositionContext& context) {
  return Run(x, internal::Job{options, context});
}

Decomposition DecomposeWithNoise(const Eigen::Ref<const Eigen::VectorXd>& x,
                                 const Eigen::Ref<const Eigen::MatrixXd>& noise,
                                 const DecompositionOptions& options,
                                 const DecompositionContext& context) {
  return Run(x, internal::Job{options, context, &noise});
}

Decomposition Emd(const Eigen::Ref<const Eigen::VectorXd>& x, const SiftingOptions& sifting,
                  int max_imfs) {
  DecompositionOptions options;
  options.method = Method::kEmd;
  options.sifting = sifting;
  options.max_imfs = max_imfs;
  return Decompose(x, options);
}

}  // namespace gyrodrift::decomposition
