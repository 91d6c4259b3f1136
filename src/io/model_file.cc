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
#include "model_json.h"

namespace gyrodrift::io {

namespace internal {

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

}  // namespace internal

namespace {

using internal::Array;
using internal::LearnerJson;
using internal::Node;
using internal::Number;
using internal::Numbers;
using internal::ReadLearner;
using internal::ReadOptions;
using internal::ReadThermal;
using internal::ThermalJson;
using nlohmann::json;
namespace dec = gyrodrift::decomposition;
namespace sel = gyrodrift::selection;

// The last format that stored thread counts (model_file.h: version 6 dropped them).
constexpr int kLastModelFormatVersionWithThreads = 5;

// ---------------------------------------------------------------------------------------------
// Writing

}  // namespace

json internal::LearnerJson(const drift::Learner& learner) {
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

namespace {

json BaselineJson(const drift::Baseline& b) {
  return {{"constant", Number(b.constant)},   {"window", b.window},
          {"alpha", Number(b.alpha)},         {"level_var", Number(b.level_var)},
          {"slope_var", Number(b.slope_var)}, {"noise_var", Number(b.noise_var)},
          {"criterion", Number(b.criterion)}};
}

json ModelJson(const drift::DriftModel& model) {
  json subs = json::array();
  for (const auto& sub : model.sub_models) {
    if (!sub.learner && !sub.mean && !sub.baseline && model.options.mode == drift::Mode::kPredict) {
      throw UsageError("sub-model '" + sub.name +
                       "' has no learner: a predict-mode model needs one per sub-model (or its "
                       "mean)");
    }
    json j = {{"name", sub.name},
              {"imfs", sub.imfs},
              {"has_residue", sub.has_residue},
              {"learner", sub.learner ? LearnerJson(*sub.learner) : json(nullptr)},
              {"thermal", sub.thermal ? ThermalJson(*sub.thermal) : json(nullptr)}};
    // Written only for a sub-model predicted by its mean, or a baseline's, so others are those
    // of version 6.
    if (sub.mean) j["mean"] = Number(*sub.mean);
    if (sub.baseline) j["baseline"] = BaselineJson(*sub.baseline);
    subs.push_back(std::move(j));
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

}  // namespace

std::shared_ptr<const drift::Learner> internal::ReadLearner(const Node& n,
                                                            const std::string& sub_name) {
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

namespace {

// model.temperature_range_c, when the file has it (files written before the range was stored have
// none: NaN, no extrapolation check).
void ReadTemperatureRange(const Node& m, drift::DriftModel& model) {
  if (!m.raw().contains("temperature_range_c")) return;
  const std::vector<double> range = m["temperature_range_c"].Doubles();
  const bool none = range.size() == 2 && std::isnan(range[0]) && std::isnan(range[1]);
  if (range.size() != 2 ||
      !(none || (std::isfinite(range[0]) && std::isfinite(range[1]) && range[0] <= range[1]))) {
    m["temperature_range_c"].Fail("must hold min <= max, finite (or both nan: no temperature)");
  }
  model.temperature_min_c = range[0];
  model.temperature_max_c = range[1];
}

// A baseline method's parameters, checked by Baseline::Validate.
std::shared_ptr<const drift::Baseline> ReadBaseline(const Node& n, drift::Method method) {
  drift::Baseline b;
  b.method = method;
  b.constant = n["constant"].Double();
  b.window = static_cast<int>(n["window"].Int(0, std::numeric_limits<int>::max()));
  b.alpha = n["alpha"].Double();
  b.level_var = n["level_var"].Double();
  b.slope_var = n["slope_var"].Double();
  b.noise_var = n["noise_var"].Double();
  b.criterion = n["criterion"].Double();
  try {
    b.Validate();
  } catch (const DataError& e) {
    n.Fail(std::string("does not rebuild: ") + e.what());
  }
  return std::make_shared<const drift::Baseline>(b);
}

// One sub-model of `model` (its options and lags read already): what it holds must suit the
// model's method and mode.
drift::SubModel ReadSubModel(const Node& s, const drift::DriftModel& model) {
  const bool predict = model.options.mode == drift::Mode::kPredict;
  drift::SubModel sub;
  sub.name = s["name"].String();
  sub.imfs = s["imfs"].Ints();
  for (int k : sub.imfs) {
    if (k < 1) s["imfs"].Fail("holds IMF " + std::to_string(k) + ": IMF indices start at 1");
  }
  sub.has_residue = s["has_residue"].Bool();
  const bool baseline = drift::IsBaseline(model.options.method);
  if (baseline != s.raw().contains("baseline")) {
    s.Fail(baseline ? "has no \"baseline\": method " +
                          std::string(drift::ToString(model.options.method)) + " needs one"
                    : "has a \"baseline\", which only a baseline method's model has");
  }
  if (baseline) sub.baseline = ReadBaseline(s["baseline"], model.options.method);
  const Node learner = s["learner"];
  if (s.raw().contains("mean")) {
    const double mean = s["mean"].Double();
    if (!std::isfinite(mean)) s["mean"].Fail("must be a finite number");
    if (!predict || !learner.IsNull()) {
      s["mean"].Fail("is for a predict-mode sub-model without a learner");
    }
    sub.mean = mean;
  } else if (learner.IsNull()) {
    if (predict && !baseline) {
      learner.Fail("is null: a predict-mode sub-model needs a learner (or a mean)");
    }
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
  return sub;
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
  ReadTemperatureRange(m, model);
  const bool predict = model.options.mode == drift::Mode::kPredict;
  if (predict && (model.lags < 1 || model.lags > 256)) {
    m["lags"].Fail("= " + std::to_string(model.lags) +
                   ": a predict-mode model needs 1 to 256 lags");
  }
  const std::vector<Node> subs = m["sub_models"].Items();
  if (subs.empty()) m["sub_models"].Fail("is empty: a model needs at least one sub-model");
  for (const Node& s : subs) model.sub_models.push_back(ReadSubModel(s, model));
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

namespace {

// The JSON of `text`, refused unless it is an object whose "format" is a model file's.
json ParseModelJson(const std::string& text, const std::string& source) {
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
  return j;
}

// The file's format_version, refused unless this version reads it.
long long ReadFormatVersion(const Node& root, const std::string& source) {
  const long long version = root["format_version"].Int(0, std::numeric_limits<int>::max());
  if (version < kOldestReadableModelFormatVersion || version > kModelFormatVersion) {
    throw DataError(source + ": model format_version " + std::to_string(version) +
                    " is not supported (this gyrodrift reads versions " +
                    std::to_string(kOldestReadableModelFormatVersion) + " to " +
                    std::to_string(kModelFormatVersion) + ")");
  }
  return version;
}

// The stored checksum, refused unless the content (all but the checksum) gives it.
std::string CheckChecksum(const json& j, const Node& root, const std::string& source) {
  const std::string stored = root["checksum"].String();
  json body = j;
  body.erase("checksum");
  const std::string computed = ChecksumText(body);
  if (stored != computed) {
    throw DataError(source + ": checksum mismatch (file says " + stored + ", content gives " +
                    computed + "): the model file is damaged or was edited");
  }
  return stored;
}

// The axis at `at` of a file of `version`; `earlier`: the axes read before it (one target each).
LoadedModel ReadAxis(const Node& at, long long version, const std::string& tool_version,
                     const std::vector<LoadedModel>& earlier) {
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
  for (const LoadedModel& e : earlier) {
    if (e.info.target_column == out.info.target_column) {
      training["target_column"].Fail("= '" + out.info.target_column +
                                     "' is the target of an earlier axis too");
    }
  }
  return out;
}

// Refuses a field of the file `j` that `axes` (read from it) written back by this version lacks:
// one that reading would silently ignore.
void RejectUnknownFields(const json& j, const std::vector<LoadedModel>& axes,
                         const std::string& stored, long long version, const std::string& source) {
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
}

}  // namespace

std::vector<LoadedModel> ParseModelFileAxes(const std::string& text, const std::string& source) {
  const json j = ParseModelJson(text, source);
  const Node root(j, "", source);
  const long long version = ReadFormatVersion(root, source);
  const std::string stored = CheckChecksum(j, root, source);
  const std::string tool_version = root["tool_version"].String();
  std::vector<LoadedModel> axes;
  if (j.contains("axes")) {
    const std::vector<Node> items = root["axes"].Items();
    if (items.size() < 2 || static_cast<int>(items.size()) > kMaxModelAxes) {
      root["axes"].Fail("holds " + std::to_string(items.size()) + " axes (2 to " +
                        std::to_string(kMaxModelAxes) +
                        " expected; a one-axis file keeps its fields at the top level)");
    }
    for (const Node& item : items) axes.push_back(ReadAxis(item, version, tool_version, axes));
  } else {
    axes.push_back(ReadAxis(root, version, tool_version, axes));
  }
  RejectUnknownFields(j, axes, stored, version, source);
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
