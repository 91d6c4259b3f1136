// The drift options in a model file (model_json.h): the decomposition with its sifting rule, the
// selection, the features, the learner and the thermal identification, written whole and read
// field by field (older formats' fields with their defaults).
#include <limits>
#include <string>

#include "gyrodrift/io/model_file.h"
#include "model_json.h"

namespace gyrodrift::io {
namespace {

using nlohmann::json;
using internal::Node;
using internal::Number;
using internal::Numbers;
using internal::ReadThermalOptions;
using internal::ThermalOptionsJson;
namespace dec = gyrodrift::decomposition;
namespace sel = gyrodrift::selection;

json SiftingJson(const dec::SiftingOptions& s) {
  return {{"stop_rule", dec::ToString(s.stop_rule)},
          {"rilling_threshold1", Number(s.rilling_threshold1)},
          {"rilling_threshold2", Number(s.rilling_threshold2)},
          {"rilling_tolerance", Number(s.rilling_tolerance)},
          {"s_number", s.s_number},
          {"fixed_sifts", s.fixed_sifts},
          {"sd_threshold", Number(s.sd_threshold)},
          {"max_sifts", s.max_sifts}};
}

json DecompositionJson(const dec::DecompositionOptions& o) {
  return {{"method", dec::ToString(o.method)},
          {"sifting", SiftingJson(o.sifting)},
          {"max_imfs", o.max_imfs},
          {"ensemble_size", o.ensemble_size},
          {"noise_strength", Number(o.noise_strength)},
          {"seed", o.seed},
          {"noise_scaling", dec::ToString(o.noise_scaling)},
          {"beemdan_bound", dec::ToString(o.beemdan_bound)},
          {"band_confidence", Number(o.band_confidence)},
          {"noise_stages", o.noise_stages}};
}

json SelectionJson(const sel::SelectionOptions& o) {
  const sel::KdeOptions& k = o.kde;
  const sel::MonteCarloOptions& m = o.monte_carlo;
  return {{"criterion", sel::ToString(o.criterion)},
          {"distance", sel::ToString(o.distance)},
          {"kde",
           {{"grid_points", k.grid_points},
            {"points_per_bandwidth", Number(k.points_per_bandwidth)},
            {"max_grid_points", k.max_grid_points},
            {"bandwidth_scale", Number(k.bandwidth_scale)},
            {"padding_bandwidths", Number(k.padding_bandwidths)},
            {"method", sel::ToString(k.method)}}},
          {"center_signal", o.center_signal},
          {"monte_carlo",
           {{"realisations", m.realisations},
            {"confidence", Number(m.confidence)},
            {"seed", m.seed},
            {"sifting", SiftingJson(m.sifting)},
            {"max_imfs", m.max_imfs}}},
          // A precomputed level only shortens the fit; the model does not need it afterwards.
          {"precomputed_noise_level", o.noise_level != nullptr},
          {"band_confidence", Number(o.band_confidence)}};
}

json LearnerOptionsJson(const drift::LearnerOptions& l) {
  const elm::ElmOptions& e = l.elm;
  return {{"kind", drift::ToString(l.kind)},
          {"elm",
           {{"hidden_units", e.hidden_units},
            {"activation", elm::ToString(e.activation)},
            {"ridge_c", Number(e.ridge_c)},
            {"solver", elm::ToString(e.solver)},
            {"selection", elm::ToString(e.selection)},
            {"hidden_unit_candidates", e.hidden_unit_candidates},
            {"ridge_c_candidates", Numbers(e.ridge_c_candidates)},
            {"max_condition", Number(e.max_condition)},
            {"standardize_inputs", e.standardize_inputs},
            {"standardize_targets", e.standardize_targets},
            {"seed", e.seed}}},
          {"poly_degree", l.poly_degree},
          {"poly_ridge", Number(l.poly_ridge)},
          {"svr_c", Number(l.svr_c)},
          {"svr_epsilon", Number(l.svr_epsilon)},
          {"svr_gamma", Number(l.svr_gamma)},
          {"svr_max_rows", l.svr_max_rows},
          {"bp_hidden", l.bp_hidden},
          {"bp_epochs", l.bp_epochs},
          {"bp_desired_mse", Number(l.bp_desired_mse)},
          {"seed", l.seed}};
}

dec::SiftingOptions ReadSifting(const Node& n) {
  dec::SiftingOptions s;
  s.stop_rule = n["stop_rule"].Enum(dec::StopRuleFromString);
  s.rilling_threshold1 = n["rilling_threshold1"].Double();
  s.rilling_threshold2 = n["rilling_threshold2"].Double();
  s.rilling_tolerance = n["rilling_tolerance"].Double();
  s.s_number = n["s_number"].Int();
  s.fixed_sifts = n["fixed_sifts"].Int();
  s.sd_threshold = n["sd_threshold"].Double();
  s.max_sifts = n["max_sifts"].Int();
  return s;
}

dec::DecompositionOptions ReadDecomposition(const Node& n) {
  dec::DecompositionOptions o;
  o.method = n["method"].Enum(dec::MethodFromString);
  o.sifting = ReadSifting(n["sifting"]);
  o.max_imfs = n["max_imfs"].Int();
  o.ensemble_size = n["ensemble_size"].Int();
  o.noise_strength = n["noise_strength"].Double();
  o.seed = n["seed"].U64();
  n.DropLegacyThreads();
  o.noise_scaling = n["noise_scaling"].Enum(dec::NoiseScalingFromString);
  o.beemdan_bound = n["beemdan_bound"].Enum(dec::BeemdanBoundFromString);
  o.band_confidence = n["band_confidence"].Double();
  o.noise_stages = n["noise_stages"].Int();
  return o;
}

sel::SelectionOptions ReadSelection(const Node& n) {
  sel::SelectionOptions o;
  o.criterion = n["criterion"].Enum(sel::CriterionFromString);
  o.distance = n["distance"].Enum(sel::PdfDistanceFromString);
  const Node k = n["kde"];
  o.kde.grid_points = k["grid_points"].Int();
  o.kde.points_per_bandwidth = k["points_per_bandwidth"].Double();
  o.kde.max_grid_points = k["max_grid_points"].Int();
  o.kde.bandwidth_scale = k["bandwidth_scale"].Double();
  o.kde.padding_bandwidths = k["padding_bandwidths"].Double();
  o.kde.method = k["method"].Enum(sel::KdeMethodFromString);
  o.center_signal = n["center_signal"].Bool();
  const Node m = n["monte_carlo"];
  o.monte_carlo.realisations = m["realisations"].Int();
  o.monte_carlo.confidence = m["confidence"].Double();
  o.monte_carlo.seed = m["seed"].U64();
  m.DropLegacyThreads();
  o.monte_carlo.sifting = ReadSifting(m["sifting"]);
  o.monte_carlo.max_imfs = m["max_imfs"].Int();
  n["precomputed_noise_level"].Bool();  // provenance only; the level is not stored
  o.band_confidence = n["band_confidence"].Double();
  n.DropLegacyThreads();
  return o;
}

drift::LearnerOptions ReadLearnerOptions(const Node& n) {
  drift::LearnerOptions l;
  l.kind = n["kind"].Enum(drift::LearnerKindFromString);
  const Node e = n["elm"];
  l.elm.hidden_units = e["hidden_units"].Int();
  l.elm.activation = e["activation"].Enum(elm::ActivationFromString);
  l.elm.ridge_c = e["ridge_c"].Double();
  l.elm.solver = e["solver"].Enum(elm::SolverFromString);
  l.elm.selection = e["selection"].Enum(elm::SelectionFromString);
  l.elm.hidden_unit_candidates = e["hidden_unit_candidates"].Ints();
  l.elm.ridge_c_candidates = e["ridge_c_candidates"].Doubles();
  l.elm.max_condition = e["max_condition"].Double();
  l.elm.standardize_inputs = e["standardize_inputs"].Bool();
  l.elm.standardize_targets = e["standardize_targets"].Bool();
  l.elm.seed = e["seed"].U64();
  e.DropLegacyThreads();
  l.poly_degree = n["poly_degree"].Int();
  l.poly_ridge = n["poly_ridge"].Double();
  l.svr_c = n["svr_c"].Double();
  l.svr_epsilon = n["svr_epsilon"].Double();
  l.svr_gamma = n["svr_gamma"].Double();
  l.svr_max_rows = n["svr_max_rows"].Int();
  l.bp_hidden = n["bp_hidden"].Ints();
  l.bp_epochs = n["bp_epochs"].Int();
  l.bp_desired_mse = n["bp_desired_mse"].Double();
  l.seed = n["seed"].U64();
  n.DropLegacyThreads();
  return l;
}

}  // namespace

drift::DriftOptions internal::ReadOptions(const Node& n) {
  drift::DriftOptions o;
  o.mode = n["mode"].Enum(drift::ModeFromString);
  o.method = n["method"].Enum(drift::MethodFromString);
  o.decomposition = ReadDecomposition(n["decomposition"]);
  o.selection = ReadSelection(n["selection"]);
  const Node f = n["features"];
  o.features.lags = f["lags"].Int();
  o.features.use_temperature = f["use_temperature"].Bool();
  o.features.time_constants_s = f["time_constants_s"].Doubles();
  o.features.rate_hz = f["rate_hz"].Double();
  // Files written before the feature set was stored were all fitted with "auto" (the CLI could
  // not choose another), which is what a missing field means.
  if (f.raw().contains("thermal_set")) {
    o.features.thermal_set = f["thermal_set"].Enum(drift::ThermalSetFromString);
  }
  // Older files stored the constants they were fitted with, all of them.
  o.features.limit_time_constants =
      f.raw().contains("limit_time_constants") && f["limit_time_constants"].Bool();
  o.learner = ReadLearnerOptions(n["learner"]);
  o.auto_lags = n["auto_lags"].Bool();
  o.lag_candidates = n["lag_candidates"].Ints();
  o.validation_fraction = n["validation_fraction"].Double();
  o.linear_compensation = n["linear_compensation"].Bool();
  // "nan": unset, keep the fitted intercept.
  if (const double reference_c = n["reference_c"].Double(); !std::isnan(reference_c)) {
    o.reference_c = reference_c;
  }
  // Files written before identification (format 2) have the defaults.
  if (n.raw().contains("thermal")) o.thermal = ReadThermalOptions(n["thermal"]);
  o.seed = n["seed"].U64();
  n.DropLegacyThreads();
  try {
    o.Validate();
  } catch (const UsageError& e) {
    n.Fail("holds an invalid option: " + std::string(e.what()));
  }
  return o;
}

nlohmann::json DriftOptionsToJson(const drift::DriftOptions& o) {
  const drift::FeatureOptions& f = o.features;
  return {{"mode", drift::ToString(o.mode)},
          {"method", drift::ToString(o.method)},
          {"decomposition", DecompositionJson(o.decomposition)},
          {"selection", SelectionJson(o.selection)},
          {"features",
           {{"lags", f.lags},
            {"use_temperature", f.use_temperature},
            {"time_constants_s", Numbers(f.time_constants_s)},
            {"rate_hz", Number(f.rate_hz)},
            {"thermal_set", drift::ToString(f.thermal_set)},
            {"limit_time_constants", f.limit_time_constants}}},
          {"learner", LearnerOptionsJson(o.learner)},
          {"auto_lags", o.auto_lags},
          {"lag_candidates", o.lag_candidates},
          {"validation_fraction", Number(o.validation_fraction)},
          {"linear_compensation", o.linear_compensation},
          // Unset: "nan", as format 5 and older wrote the NaN that meant it.
          {"reference_c", o.reference_c ? Number(*o.reference_c) : json("nan")},
          {"thermal", ThermalOptionsJson(o.thermal)},
          {"seed", o.seed}};
}

drift::DriftOptions DriftOptionsFromJson(const nlohmann::json& json, const std::string& source) {
  return ReadOptions(Node(json, "options", source));
}

}  // namespace gyrodrift::io
