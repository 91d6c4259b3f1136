#include "gyrodrift/io/model_file.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/version.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::io {
namespace {

using nlohmann::json;
namespace dec = gyrodrift::decomposition;
namespace sel = gyrodrift::selection;

// The last format that stored thread counts (model_file.h: version 6 dropped them).
constexpr int kLastModelFormatVersionWithThreads = 5;

// ---------------------------------------------------------------------------------------------
// Writing

json Number(double v) {
  if (std::isfinite(v)) return v;
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

json Numbers(const std::vector<double>& values) {
  json out = json::array();
  for (double v : values) out.push_back(Number(v));
  return out;
}

json Array(const Eigen::MatrixXd& m) {
  json data = json::array();
  // Eigen's default storage is column-major, so data() walks the documented order.
  for (Eigen::Index i = 0; i < m.size(); ++i) data.push_back(Number(m.data()[i]));
  return {{"rows", m.rows()}, {"cols", m.cols()}, {"data", std::move(data)}};
}

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

json LearnerJson(const drift::Learner& learner) {
  const drift::Parameters p = learner.Save();
  json arrays = json::object(), scalars = json::object(), texts = json::object();
  for (const auto& [name, m] : p.arrays) arrays[name] = Array(m);
  for (const auto& [name, v] : p.scalars) scalars[name] = Number(v);
  for (const auto& [name, t] : p.texts) texts[name] = t;
  return {{"kind", drift::ToString(learner.kind())},
          {"arrays", std::move(arrays)},
          {"scalars", std::move(scalars)},
          {"texts", std::move(texts)}};
}

json ThermalOptionsJson(const drift::ThermalModelOptions& t) {
  return {{"shortest_tau_s", Number(t.shortest_tau_s)},
          {"longest_tau_s", Number(t.longest_tau_s)},
          {"taus_per_octave", t.taus_per_octave},
          {"longest_tau_share", Number(t.longest_tau_share)},
          {"max_states", t.max_states},
          {"state_order", t.state_order},
          {"max_power", t.max_power},
          {"folds", t.folds},
          {"folds_at_regimes", t.folds_at_regimes},
          {"ramp_rate_k_per_min", Number(t.ramp_rate_k_per_min)},
          {"hysteresis", drift::ToString(t.hysteresis)},
          {"hysteresis_widths_k", Numbers(t.hysteresis_widths_k)},
          {"max_condition", Number(t.max_condition)},
          {"standard_errors", Number(t.standard_errors)}};
}

json ThermalJson(const drift::ThermalRegression& t) {
  json states = json::array();
  for (const auto& s : t.states) {
    states.push_back({{"channel", s.channel},
                      {"tau_s", Number(s.tau_s)},
                      {"level_range", Numbers({s.level_min, s.level_max})},
                      {"rate_range", Numbers({s.rate_min, s.rate_max})}});
  }
  json static_range = json::array();
  for (size_t c = 0; c < t.static_min.size(); ++c) {
    static_range.push_back(Numbers({t.static_min[c], t.static_max[c]}));
  }
  const drift::CalibrationReport& r = t.report;
  json j = {{"rate_hz", Number(t.rate_hz)},
          {"order", t.order},
          {"max_power", t.max_power},
          {"centre_c", Numbers(t.centre_c)},
          {"scale_k", Numbers(t.scale_k)},
          {"static_power", t.static_power},
          {"static_range", std::move(static_range)},
          {"states", std::move(states)},
          {"hysteresis", t.has_hysteresis() ? json{{"state", t.hysteresis_state},
                                                   {"width_k", Number(t.hysteresis_width_k)}}
                                            : json(nullptr)},
          {"regressors", t.RegressorNames()},
          {"coefficients", Array(t.coefficients)},
          {"covariance", Array(t.covariance)},
          {"cv_slow_sd", Number(t.cv_slow_sd)},
          {"correction", t.correction ? LearnerJson(*t.correction) : json(nullptr)},
          {"report",
           {{"duration_s", Number(r.duration_s)},
            {"span_k", Numbers(r.span_k)},
            {"max_heating_k_per_min", Number(r.max_heating_k_per_min)},
            {"max_cooling_k_per_min", Number(r.max_cooling_k_per_min)},
            {"ramps", r.ramps},
            {"dwells", r.dwells},
            {"folds", r.folds},
            {"cv_rmse", Number(r.cv_rmse)},
            {"cv_rmse_constant", Number(r.cv_rmse_constant)},
            {"skill", Number(r.skill)},
            {"condition", Number(r.condition)},
            {"level", r.level},
            {"best_level", r.best_level},
            {"regime_folds", r.regime_folds},
            {"range_folds", r.range_folds},
            {"held_out_rmse", Number(r.held_out_rmse)},
            {"held_out_rmse_constant", Number(r.held_out_rmse_constant)},
            {"held_out_rmse_static", Number(r.held_out_rmse_static)},
            {"held_out_rmse_best", Number(r.held_out_rmse_best)},
            {"regime_rmse", Number(r.regime_rmse)},
            {"regime_rmse_constant", Number(r.regime_rmse_constant)},
            {"regime_rmse_static", Number(r.regime_rmse_static)},
            {"advice", r.advice},
            {"nonlinear_units", r.nonlinear_units},
            {"hysteresis_tried", r.hysteresis_tried},
            {"nonlinear_ridge_c", Number(r.nonlinear_ridge_c)},
            {"cv_rmse_nonlinear", Number(r.cv_rmse_nonlinear)},
            {"warnings", r.warnings}}}};
  // Written only for a fit on several records, so a one-record model's file is unchanged.
  if (r.records > 1) j["report"]["records"] = r.records;
  return j;
}

json ModelJson(const drift::DriftModel& model) {
  json subs = json::array();
  for (const auto& sub : model.sub_models) {
    if (!sub.learner && model.options.mode == drift::Mode::kPredict) {
      throw UsageError("sub-model '" + sub.name +
                       "' has no learner: a predict-mode model needs one per sub-model");
    }
    subs.push_back({{"name", sub.name},
                    {"imfs", sub.imfs},
                    {"has_residue", sub.has_residue},
                    {"learner", sub.learner ? LearnerJson(*sub.learner) : json(nullptr)},
                    {"thermal", sub.thermal ? ThermalJson(*sub.thermal) : json(nullptr)}});
  }
  return {{"lags", model.lags},
          {"training_imfs", model.training_imfs},
          {"training_samples", model.training_samples},
          {"decomposition_summary", model.decomposition_summary},
          {"selection_summary", model.selection_summary},
          {"lag_validation_rmse", Numbers(model.lag_validation_rmse)},
          {"temperature_range_c", Numbers({model.temperature_min_c, model.temperature_max_c})},
          {"sub_models", std::move(subs)}};
}

std::string Hex64(std::uint64_t v) {
  char buffer[17];
  std::snprintf(buffer, sizeof(buffer), "%016llx", static_cast<unsigned long long>(v));
  return buffer;
}

// The text the checksum covers: compact, keys sorted (nlohmann objects are ordered maps), and
// invalid UTF-8 in names replaced the same way on writing and reading.
std::string Canonical(const json& j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string ChecksumText(const json& without_checksum) {
  return "fnv1a64:" + Hex64(Fnv1a64(Canonical(without_checksum)));
}

// ---------------------------------------------------------------------------------------------
// Reading: every access names the file and the dotted path of the field.

class Node {
 public:
  Node(const json& j, std::string path, const std::string& source)
      : j_(j), path_(std::move(path)), source_(source) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw DataError(source_ + ": field '" + path_ + "' " + what);
  }

  Node operator[](const std::string& key) const {
    if (!j_.is_object()) Fail("must be an object (found " + std::string(j_.type_name()) + ")");
    const auto it = j_.find(key);
    const std::string path = path_.empty() ? key : path_ + "." + key;
    if (it == j_.end()) throw DataError(source_ + ": field '" + path + "' is missing");
    return Node(*it, path, source_);
  }

  bool IsNull() const { return j_.is_null(); }
  const json& raw() const { return j_; }

  // Files of format 5 and older hold thread counts beside the options, the fit's execution rather
  // than the model: "threads" is read (a non-negative integer) and dropped if present.
  // ParseModelFileAxes refuses the field in newer files.
  void DropLegacyThreads() const {
    if (j_.is_object() && j_.contains("threads")) {
      (*this)["threads"].Int(0, std::numeric_limits<int>::max());
    }
  }

  double Double() const {
    if (j_.is_number()) return j_.get<double>();
    if (j_.is_string()) {
      const std::string& s = j_.get_ref<const std::string&>();
      if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
      if (s == "inf") return std::numeric_limits<double>::infinity();
      if (s == "-inf") return -std::numeric_limits<double>::infinity();
    }
    Fail("must be a number (found " + Found() + ")");
  }

  long long Int(long long lo, long long hi) const {
    if (!j_.is_number_integer()) Fail("must be an integer (found " + Found() + ")");
    if (j_.is_number_unsigned() && j_.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      Fail("= " + j_.dump() + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
           "]");
    }
    const long long v = j_.get<long long>();
    if (v < lo || v > hi) {
      Fail("= " + std::to_string(v) + ": must be in [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    }
    return v;
  }
  int Int() const {
    return static_cast<int>(Int(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  }

  std::uint64_t U64() const {
    if (!j_.is_number_unsigned()) Fail("must be an unsigned integer (found " + Found() + ")");
    return j_.get<std::uint64_t>();
  }

  bool Bool() const {
    if (!j_.is_boolean()) Fail("must be true or false (found " + Found() + ")");
    return j_.get<bool>();
  }

  std::string String() const {
    if (!j_.is_string()) Fail("must be a string (found " + Found() + ")");
    return j_.get<std::string>();
  }

  std::vector<Node> Items() const {
    if (!j_.is_array()) Fail("must be an array (found " + Found() + ")");
    std::vector<Node> items;
    for (size_t i = 0; i < j_.size(); ++i) {
      items.emplace_back(j_[i], path_ + "[" + std::to_string(i) + "]", source_);
    }
    return items;
  }

  std::vector<int> Ints() const {
    std::vector<int> out;
    for (const Node& n : Items()) out.push_back(n.Int());
    return out;
  }
  std::vector<double> Doubles() const {
    std::vector<double> out;
    for (const Node& n : Items()) out.push_back(n.Double());
    return out;
  }

  // An enum through its FromString, whose UsageError becomes a DataError naming the field.
  template <class F>
  auto Enum(F from_string) const -> decltype(from_string(std::string_view())) {
    const std::string text = String();
    try {
      return from_string(text);
    } catch (const UsageError& e) {
      Fail("= '" + text + "' is not understood (" + e.what() + ")");
    }
  }

  Eigen::MatrixXd Matrix() const {
    const long long max_size = 1LL << 31;
    const long long rows = (*this)["rows"].Int(0, max_size);
    const long long cols = (*this)["cols"].Int(0, max_size);
    const std::vector<Node> data = (*this)["data"].Items();
    if (static_cast<long long>(data.size()) != rows * cols) {
      Fail("has " + std::to_string(data.size()) + " values for a " + std::to_string(rows) + " x " +
           std::to_string(cols) + " array (rows * cols expected)");
    }
    Eigen::MatrixXd m(rows, cols);
    for (size_t i = 0; i < data.size(); ++i) m.data()[i] = data[i].Double();
    return m;
  }

 private:
  std::string Found() const {
    if (j_.is_string()) return "\"" + j_.get<std::string>() + "\"";
    if (j_.is_number() || j_.is_boolean() || j_.is_null()) return j_.dump();
    return j_.type_name();
  }

  const json& j_;
  std::string path_;
  const std::string& source_;
};

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

std::shared_ptr<const drift::Learner> ReadLearner(const Node& n, const std::string& sub_name) {
  const drift::LearnerKind kind = n["kind"].Enum(drift::LearnerKindFromString);
  for (const char* key : {"arrays", "scalars", "texts"}) {
    if (!n[key].raw().is_object()) n[key].Fail("must be an object");
  }
  drift::Parameters p;
  for (const auto& [name, value] : n["arrays"].raw().items()) {
    p.arrays[name] = n["arrays"][name].Matrix();
  }
  for (const auto& [name, value] : n["scalars"].raw().items()) {
    p.scalars[name] = n["scalars"][name].Double();
  }
  for (const auto& [name, value] : n["texts"].raw().items()) {
    p.texts[name] = n["texts"][name].String();
  }
  try {
    return drift::LoadLearner(kind, p);
  } catch (const Error& e) {
    n.Fail("(learner of sub-model '" + sub_name + "') does not rebuild: " + e.what());
  }
}

drift::ThermalModelOptions ReadThermalOptions(const Node& n) {
  drift::ThermalModelOptions t;
  t.shortest_tau_s = n["shortest_tau_s"].Double();
  t.longest_tau_s = n["longest_tau_s"].Double();
  t.taus_per_octave = n["taus_per_octave"].Int();
  t.longest_tau_share = n["longest_tau_share"].Double();
  t.max_states = n["max_states"].Int();
  t.state_order = n["state_order"].Int();
  t.max_power = n["max_power"].Int();
  t.folds = n["folds"].Int();
  t.folds_at_regimes = n["folds_at_regimes"].Bool();
  t.ramp_rate_k_per_min = n["ramp_rate_k_per_min"].Double();
  // Files before version 5 were identified without the hysteresis term.
  t.hysteresis = n.raw().contains("hysteresis")
                     ? n["hysteresis"].Enum(drift::HysteresisTermFromString)
                     : drift::HysteresisTerm::kOff;
  if (n.raw().contains("hysteresis_widths_k")) {
    t.hysteresis_widths_k = n["hysteresis_widths_k"].Doubles();
  }
  // Files before version 7 chose the richest structure of least error, without these rules.
  if (n.raw().contains("max_condition")) {
    t.max_condition = n["max_condition"].Double();
    t.standard_errors = n["standard_errors"].Double();
  }
  return t;
}

std::shared_ptr<const drift::ThermalRegression> ReadThermal(const Node& n) {
  auto t = std::make_shared<drift::ThermalRegression>();
  t->rate_hz = n["rate_hz"].Double();
  t->order = n["order"].Int(1, 4);
  t->max_power = n["max_power"].Int(1, 3);
  t->centre_c = n["centre_c"].Doubles();
  t->scale_k = n["scale_k"].Doubles();
  auto pair = [](const Node& node) {
    const std::vector<double> range = node.Doubles();
    if (range.size() != 2) node.Fail("must hold [min, max]");
    return std::pair{range[0], range[1]};
  };
  if (n.raw().contains("static_power")) {
    for (const Node& p : n["static_power"].Items()) {
      t->static_power.push_back(static_cast<int>(p.Int(0, 3)));
    }
    for (const Node& r : n["static_range"].Items()) {
      const auto [lo, hi] = pair(r);
      t->static_min.push_back(lo);
      t->static_max.push_back(hi);
    }
  } else {  // before version 7: a linear term per channel, unbounded
    for (const Node& b : n["linear"].Items()) {
      t->static_power.push_back(b.Bool() ? 1 : 0);
      t->static_min.push_back(-std::numeric_limits<double>::infinity());
      t->static_max.push_back(std::numeric_limits<double>::infinity());
    }
  }
  for (const Node& s : n["states"].Items()) {
    drift::ThermalState state{static_cast<int>(s["channel"].Int(0, 1024)), s["tau_s"].Double()};
    std::tie(state.level_min, state.level_max) = pair(s["level_range"]);
    // Before version 7 the rates ran unheld.
    if (s.raw().contains("rate_range")) std::tie(state.rate_min, state.rate_max) = pair(s["rate_range"]);
    t->states.push_back(state);
  }
  if (n.raw().contains("hysteresis") && !n["hysteresis"].IsNull()) {
    const Node h = n["hysteresis"];
    t->hysteresis_state = static_cast<int>(h["state"].Int(0, 1024));
    t->hysteresis_width_k = h["width_k"].Double();
  }
  const Eigen::MatrixXd coefficients = n["coefficients"].Matrix();
  if (coefficients.cols() != 1) n["coefficients"].Fail("must be a column (cols = 1)");
  t->coefficients = coefficients.col(0);
  t->covariance = n["covariance"].Matrix();
  t->cv_slow_sd = n["cv_slow_sd"].Double();
  const Node r = n["report"];
  drift::CalibrationReport& report = t->report;
  report.duration_s = r["duration_s"].Double();
  report.records = r.raw().contains("records") ? r["records"].Int(2, 1000000000) : 1;
  report.span_k = r["span_k"].Doubles();
  report.max_heating_k_per_min = r["max_heating_k_per_min"].Double();
  report.max_cooling_k_per_min = r["max_cooling_k_per_min"].Double();
  report.ramps = r["ramps"].Int();
  report.dwells = r["dwells"].Int();
  report.folds = r["folds"].Int();
  report.cv_rmse = r["cv_rmse"].Double();
  report.cv_rmse_constant = r["cv_rmse_constant"].Double();
  report.skill = r["skill"].Double();
  report.condition = r["condition"].Double();
  if (r.raw().contains("level")) {  // version 7
    report.level = static_cast<int>(r["level"].Int(0, drift::CalibrationReport::kHysteresis));
    report.best_level =
        static_cast<int>(r["best_level"].Int(0, drift::CalibrationReport::kHysteresis));
    report.regime_folds = static_cast<int>(r["regime_folds"].Int(0, 1000000));
    report.range_folds = static_cast<int>(r["range_folds"].Int(0, 2));
    report.held_out_rmse = r["held_out_rmse"].Double();
    report.held_out_rmse_constant = r["held_out_rmse_constant"].Double();
    report.held_out_rmse_static = r["held_out_rmse_static"].Double();
    report.held_out_rmse_best = r["held_out_rmse_best"].Double();
    report.regime_rmse = r["regime_rmse"].Double();
    report.regime_rmse_constant = r["regime_rmse_constant"].Double();
    report.regime_rmse_static = r["regime_rmse_static"].Double();
    for (const Node& a : r["advice"].Items()) report.advice.push_back(a.String());
  }
  report.nonlinear_units = r["nonlinear_units"].Int(0, 100000);
  report.hysteresis_tried = r.raw().contains("hysteresis_tried") && r["hysteresis_tried"].Bool();
  report.nonlinear_ridge_c = r["nonlinear_ridge_c"].Double();
  report.cv_rmse_nonlinear = r["cv_rmse_nonlinear"].Double();
  for (const Node& w : r["warnings"].Items()) report.warnings.push_back(w.String());
  if (!n["correction"].IsNull()) t->correction = ReadLearner(n["correction"], "correction");
  try {
    t->Validate();
  } catch (const DataError& e) {
    n.Fail(std::string("does not rebuild: ") + e.what());
  }
  if (n["regressors"].raw() != json(t->RegressorNames())) {
    n["regressors"].Fail("does not match the states and channels stored");
  }
  return t;
}

drift::DriftOptions ReadOptions(const Node& n) {
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

drift::DriftModel ReadModel(const Node& root) {
  drift::DriftModel model;
  model.options = ReadOptions(root["options"]);
  const Node m = root["model"];
  model.lags = m["lags"].Int();
  model.training_imfs = m["training_imfs"].Int();
  model.training_samples = static_cast<Eigen::Index>(m["training_samples"].Int(0, 1LL << 40));
  model.decomposition_summary = m["decomposition_summary"].String();
  model.selection_summary = m["selection_summary"].String();
  model.lag_validation_rmse = m["lag_validation_rmse"].Doubles();
  // Files written before the range was stored have none (NaN: no extrapolation check).
  if (m.raw().contains("temperature_range_c")) {
    const std::vector<double> range = m["temperature_range_c"].Doubles();
    const bool none = range.size() == 2 && std::isnan(range[0]) && std::isnan(range[1]);
    if (range.size() != 2 ||
        !(none || (std::isfinite(range[0]) && std::isfinite(range[1]) && range[0] <= range[1]))) {
      m["temperature_range_c"].Fail("must hold min <= max, finite (or both nan: no temperature)");
    }
    model.temperature_min_c = range[0];
    model.temperature_max_c = range[1];
  }
  const bool predict = model.options.mode == drift::Mode::kPredict;
  if (predict && (model.lags < 1 || model.lags > 256)) {
    m["lags"].Fail("= " + std::to_string(model.lags) +
                   ": a predict-mode model needs 1 to 256 lags");
  }
  const std::vector<Node> subs = m["sub_models"].Items();
  if (subs.empty()) m["sub_models"].Fail("is empty: a model needs at least one sub-model");
  for (const Node& s : subs) {
    drift::SubModel sub;
    sub.name = s["name"].String();
    sub.imfs = s["imfs"].Ints();
    for (int k : sub.imfs) {
      if (k < 1) s["imfs"].Fail("holds IMF " + std::to_string(k) + ": IMF indices start at 1");
    }
    sub.has_residue = s["has_residue"].Bool();
    const Node learner = s["learner"];
    if (learner.IsNull()) {
      if (predict) learner.Fail("is null: a predict-mode sub-model needs a learner");
    } else {
      sub.learner = ReadLearner(learner, sub.name);
      if (sub.learner->num_inputs() != model.num_inputs()) {
        learner.Fail("takes " + std::to_string(sub.learner->num_inputs()) +
                     " inputs, the model's options give " + std::to_string(model.num_inputs()));
      }
    }
    if (s.raw().contains("thermal") && !s["thermal"].IsNull()) {
      if (predict) s["thermal"].Fail("is a thermal model, which only a compensate-mode model has");
      sub.thermal = ReadThermal(s["thermal"]);
    }
    model.sub_models.push_back(std::move(sub));
  }
  int channels = 0;
  for (const drift::SubModel& sub : model.sub_models) {
    if (!sub.thermal) continue;
    if (channels != 0 && sub.thermal->channels() != channels) {
      m["sub_models"].Fail("holds thermal models of different channel counts");
    }
    channels = sub.thermal->channels();
  }
  return model;
}

}  // namespace

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

namespace {

// One axis: what it was trained on, its options and its parameters.
json AxisJson(const LoadedModel& axis) {
  const drift::DriftModel& model = axis.model;
  return {{"training",
           {{"target_column", axis.info.target_column},
            {"temperature_column", axis.info.temperature_column},
            {"rate_unit", axis.info.rate_unit},
            {"samples", model.training_samples},
            {"source", axis.info.source}}},
          {"options", DriftOptionsToJson(model.options)},
          {"model", ModelJson(model)}};
}

// The file's content but the checksum: one axis at the top level (the layout of every version),
// several under "axes".
json ModelFileJson(const std::vector<LoadedModel>& axes) {
  if (axes.empty()) throw UsageError("a model file needs at least one axis");
  if (static_cast<int>(axes.size()) > kMaxModelAxes) {
    throw UsageError("a model file holds at most " + std::to_string(kMaxModelAxes) + " axes, not " +
                     std::to_string(axes.size()));
  }
  for (size_t i = 0; i < axes.size(); ++i) {
    for (size_t k = 0; k < i; ++k) {
      if (axes[i].info.target_column == axes[k].info.target_column) {
        throw UsageError("two axes of one model file share the target column '" +
                         axes[i].info.target_column + "'");
      }
    }
  }
  json j = {{"format", kModelFormat},
            {"format_version", kModelFormatVersion},
            {"tool_version", kVersion}};
  if (axes.size() == 1) {
    j.update(AxisJson(axes[0]));
  } else {
    j["axes"] = json::array();
    for (const LoadedModel& axis : axes) j["axes"].push_back(AxisJson(axis));
  }
  return j;
}

}  // namespace

std::string RenderModelFile(const std::vector<LoadedModel>& axes) {
  json j = ModelFileJson(axes);
  j["checksum"] = ChecksumText(j);
  return j.dump(1, ' ', false, json::error_handler_t::replace) + "\n";
}

std::string RenderModelFile(const drift::DriftModel& model, const ModelFileInfo& info) {
  return RenderModelFile({LoadedModel{model, info}});
}

void WriteModelFile(const std::string& path, const std::vector<LoadedModel>& axes) {
  WriteFileAtomically(path, RenderModelFile(axes));
}

void WriteModelFile(const std::string& path, const drift::DriftModel& model,
                    const ModelFileInfo& info) {
  WriteFileAtomically(path, RenderModelFile(model, info));
}

// The dotted path of the first field of `file` that `known` (the same model written back by
// this version) lacks, or "" when there is none. Values are not compared, only field names, so
// a misspelt or invented field, which reading would silently ignore, is caught.
std::string FirstUnknownField(const json& file, const json& known, const std::string& path) {
  if (file.is_object() && known.is_object()) {
    for (const auto& [key, value] : file.items()) {
      const std::string here = path.empty() ? key : path + "." + key;
      const auto it = known.find(key);
      if (it == known.end()) return here;
      const std::string inner = FirstUnknownField(value, *it, here);
      if (!inner.empty()) return inner;
    }
  } else if (file.is_array() && known.is_array()) {
    for (size_t i = 0; i < file.size() && i < known.size(); ++i) {
      const std::string inner =
          FirstUnknownField(file[i], known[i], path + "[" + std::to_string(i) + "]");
      if (!inner.empty()) return inner;
    }
  }
  return "";
}

std::vector<LoadedModel> ParseModelFileAxes(const std::string& text, const std::string& source) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw DataError(source + ": not a gyrodrift model file (not valid JSON: byte " +
                    std::to_string(e.byte) + ")");
  } catch (const json::exception& e) {
    // A number out of double's range and the like (found by tests/fuzz/fuzz_model_file).
    throw DataError(source + ": not a gyrodrift model file (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("format") || !j["format"].is_string() ||
      j["format"].get<std::string>() != kModelFormat) {
    throw DataError(source + ": not a gyrodrift model file (\"format\" must be \"" +
                    std::string(kModelFormat) + "\")");
  }
  const Node root(j, "", source);
  const long long version = root["format_version"].Int(0, std::numeric_limits<int>::max());
  if (version < kOldestReadableModelFormatVersion || version > kModelFormatVersion) {
    throw DataError(source + ": model format_version " + std::to_string(version) +
                    " is not supported (this gyrodrift reads versions " +
                    std::to_string(kOldestReadableModelFormatVersion) + " to " +
                    std::to_string(kModelFormatVersion) + ")");
  }
  const std::string stored = root["checksum"].String();
  json body = j;
  body.erase("checksum");
  const std::string computed = ChecksumText(body);
  if (stored != computed) {
    throw DataError(source + ": checksum mismatch (file says " + stored + ", content gives " +
                    computed + "): the model file is damaged or was edited");
  }
  const std::string tool_version = root["tool_version"].String();
  std::vector<LoadedModel> axes;
  auto read_axis = [&](const Node& at) {
    LoadedModel out;
    out.info.tool_version = tool_version;
    const Node training = at["training"];
    out.info.target_column = training["target_column"].String();
    out.info.temperature_column = training["temperature_column"].String();
    out.info.source = training["source"].String();
    out.info.rate_unit = "";
    if (version >= 4) {
      out.info.rate_unit = training["rate_unit"].String();
      if (!out.info.rate_unit.empty()) {
        try {
          (void)allan::RateUnitFromString(out.info.rate_unit);
        } catch (const UsageError&) {
          training["rate_unit"].Fail("= '" + out.info.rate_unit + "': must be dph, dps or rads");
        }
      }
    }
    out.model = ReadModel(at);
    if (training["samples"].Int(0, 1LL << 40) != out.model.training_samples) {
      training["samples"].Fail("differs from model.training_samples");
    }
    if (out.model.uses_temperature() && out.info.temperature_column.empty()) {
      training["temperature_column"].Fail("is empty but the model uses temperature");
    }
    for (const LoadedModel& earlier : axes) {
      if (earlier.info.target_column == out.info.target_column) {
        training["target_column"].Fail("= '" + out.info.target_column +
                                       "' is the target of an earlier axis too");
      }
    }
    axes.push_back(std::move(out));
  };
  if (j.contains("axes")) {
    const std::vector<Node> items = root["axes"].Items();
    if (items.size() < 2 || static_cast<int>(items.size()) > kMaxModelAxes) {
      root["axes"].Fail("holds " + std::to_string(items.size()) + " axes (2 to " +
                        std::to_string(kMaxModelAxes) +
                        " expected; a one-axis file keeps its fields at the top level)");
    }
    for (const Node& item : items) read_axis(item);
  } else {
    read_axis(root);
  }
  json known = ModelFileJson(axes);
  known["checksum"] = stored;
  if (version <= kLastModelFormatVersionWithThreads) {
    // Their thread counts, checked and dropped on reading above.
    auto add_threads = [](json& axis) {
      json& o = axis["options"];
      for (json* at : {&o, &o["decomposition"], &o["selection"], &o["selection"]["monte_carlo"],
                       &o["learner"], &o["learner"]["elm"]}) {
        (*at)["threads"] = 0;
      }
      for (json& sub : axis["model"]["sub_models"]) {
        if (!sub["learner"].is_null()) sub["learner"]["scalars"]["threads"] = 0;
      }
    };
    if (known.contains("axes")) {
      for (json& axis : known["axes"]) add_threads(axis);
    } else {
      add_threads(known);
    }
  }
  const std::string unknown = FirstUnknownField(j, known, "");
  if (!unknown.empty()) {
    throw DataError(source + ": field '" + unknown +
                    "' is not part of a gyrodrift model file (misspelt, or from another tool)");
  }
  return axes;
}

LoadedModel ParseModelFile(const std::string& text, const std::string& source) {
  std::vector<LoadedModel> axes = ParseModelFileAxes(text, source);
  if (axes.size() != 1) {
    std::string names;
    for (const LoadedModel& axis : axes) {
      names += (names.empty() ? "" : ", ") + axis.info.target_column;
    }
    throw UsageError(source + " holds " + std::to_string(axes.size()) + " axes (" + names +
                     "): this command reads one-axis models; fit each axis apart");
  }
  return std::move(axes[0]);
}

std::vector<LoadedModel> ReadModelFileAxes(const std::string& path) {
  return ParseModelFileAxes(ReadTextFile(path), path);
}

LoadedModel ReadModelFile(const std::string& path) {
  return ParseModelFile(ReadTextFile(path), path);
}

}  // namespace gyrodrift::io
