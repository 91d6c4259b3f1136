#include "gyrodrift/tasks/decompose_task.h"

#include <fmt/core.h>

#include <utility>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::tasks {

namespace dec = gyrodrift::decomposition;

dec::DecompositionOptions DecomposeSettings::Options() const {
  dec::DecompositionOptions o;
  // A refusal names the setting the user gave (ensemble, as Python's keyword and the CLI's flag
  // spell it), not the library's field (ensemble_size).
  ValidateAsSettings({{"stop_rule", "stop"},
                      {"sifting.stop_rule", "stop"},
                      {"sifting.max_sifts", "max_sifts"},
                      {"sifting.s_number", "s_number"},
                      {"sifting.fixed_sifts", "fixed_sifts"},
                      {"sifting.sd_threshold", "sd"},
                      {"ensemble_size", "ensemble"},
                      {"noise_strength", "noise"},
                      {"beemdan_bound", "bound"},
                      {"band_confidence", "band"}},
                     [&] {
                       o.method = dec::MethodFromString(method);
                       o.sifting.stop_rule = dec::StopRuleFromString(stop);
                       o.sifting.max_sifts = max_sifts;
                       o.sifting.s_number = s_number;
                       o.sifting.fixed_sifts = fixed_sifts;
                       o.sifting.sd_threshold = sd;
                       o.max_imfs = max_imfs;
                       o.ensemble_size = ensemble;
                       o.noise_strength = noise;
                       o.seed = seed;
                       o.noise_scaling = dec::NoiseScalingFromString(noise_scaling);
                       o.beemdan_bound = dec::BeemdanBoundFromString(bound);
                       o.band_confidence = band;
                       o.noise_stages = noise_stages;
                       o.Validate();
                     });
  return o;
}

dec::DecompositionContext DecomposeSettings::Context(
    std::function<void(double, std::string_view)> progress) const {
  dec::DecompositionContext context;
  context.execution.threads = threads;
  context.execution.Validate();
  context.execution.progress = std::move(progress);
  return context;
}

void DecomposeSettings::Validate() const {
  Options();
  Context();
}

void RequireNoiseTaken(const DecomposeSettings& settings, std::string_view noise_name) {
  if (dec::MethodFromString(settings.method) == dec::Method::kEmd) {
    throw UsageError(std::string(noise_name) + ": must not be given with " +
                     (noise_name.starts_with("--") ? "--method emd" : "method='emd'"));
  }
}

void RequireDecomposable(const Eigen::VectorXd& x, std::string_view signal_name) {
  if (x.size() < dec::kMinDecomposeSamples) {
    throw DataError(fmt::format("{} has {} sample{}: decompose needs at least {}", signal_name,
                                x.size(), x.size() == 1 ? "" : "s", dec::kMinDecomposeSamples));
  }
  RequireVaryingSignal(signal_name, x, "it has no oscillation to decompose");
  if (x.size() > kMaxDecomposeSamples) {
    throw DataError(fmt::format(
        "{} has {} samples: decompose takes at most {} (memory grows with samples x modes; "
        "decimate or split the log)",
        signal_name, x.size(), kMaxDecomposeSamples));
  }
}

dec::Decomposition RunDecompose(const Eigen::VectorXd& x, const DecomposeSettings& settings,
                                const Eigen::MatrixXd& noise,
                                std::function<void(double, std::string_view)> progress,
                                std::string_view noise_name, std::string_view signal_name) {
  dec::DecompositionOptions o = settings.Options();
  RequireDecomposable(x, signal_name);
  const dec::DecompositionContext context = settings.Context(std::move(progress));
  if (noise.size() == 0) return dec::Decompose(x, o, context);
  RequireNoiseTaken(settings, noise_name);
  o.ensemble_size = static_cast<int>(noise.cols());
  return dec::DecomposeWithNoise(x, noise, o, context);
}

nlohmann::json DecomposeOptionsRecord(const DecomposeSettings& settings,
                                      Eigen::Index noise_columns) {
  dec::DecompositionOptions o = settings.Options();
  if (noise_columns > 0) o.ensemble_size = static_cast<int>(noise_columns);
  return {
      {"method", dec::ToString(o.method)},
      {"stop_rule", dec::ToString(o.sifting.stop_rule)},
      {"rilling_thresholds",
       {o.sifting.rilling_threshold1, o.sifting.rilling_threshold2, o.sifting.rilling_tolerance}},
      {"s_number", o.sifting.s_number},
      {"fixed_sifts", o.sifting.fixed_sifts},
      {"sd_threshold", o.sifting.sd_threshold},
      {"max_sifts", o.sifting.EffectiveMaxSifts()},
      {"max_imfs", o.max_imfs},
      {"ensemble_size", o.ensemble_size},
      {"noise_strength", o.noise_strength},
      {"seed", o.seed},
      {"threads", settings.threads},
      {"noise_scaling", dec::ToString(o.noise_scaling)},
      {"beemdan_bound", dec::ToString(o.beemdan_bound)},
      {"band_confidence", o.band_confidence},
      {"noise_stages", o.noise_stages},
  };
}

nlohmann::json DecomposeReportRecord(const dec::Decomposition& d) {
  const dec::DecompositionReport& r = d.report;
  return {
      {"summary", r.Summary()},
      {"imfs", d.num_imfs()},
      {"sifts_per_imf", r.sifts_per_imf},
      {"sift_cap_hit", r.sift_cap_hit},
      {"sift_cap_hits", r.sift_cap_hits},
      {"ensemble_size", r.ensemble_size},
      {"seed", r.seed},
      {"threads_used", r.threads},
      {"supplied_noise", r.supplied_noise},
      {"noise_assisted_stages", r.noise_assisted_stages},
      {"stop_reason", r.stop_reason},
      {"mode_log2_energy", r.mode_log2_energy},
      {"noise_band_log2_upper", r.noise_band_log2_upper},
  };
}

}  // namespace gyrodrift::tasks
