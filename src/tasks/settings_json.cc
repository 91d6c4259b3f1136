#include "gyrodrift/tasks/settings_json.h"

#include <algorithm>
#include <functional>
#include <optional>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/ulog.h"

namespace gyrodrift::tasks {
namespace {

using nlohmann::json;

// One field: its key, how it is written, how it is read (checking the value's type).
template <class T>
struct Field {
  const char* key;
  std::function<json(const T&)> write;
  std::function<void(const json&, T&)> read;
};

[[noreturn]] void Wrong(const char* key, const json& v, const char* rule) {
  ThrowOption(key, v.dump(), rule);
}
std::string String(const char* key, const json& v) {
  if (!v.is_string()) Wrong(key, v, "a string");
  return v.get<std::string>();
}
std::vector<std::string> Strings(const char* key, const json& v) {
  if (!v.is_array()) Wrong(key, v, "an array of strings");
  std::vector<std::string> out;
  for (const json& item : v) out.push_back(String(key, item));
  return out;
}
std::vector<double> Numbers(const char* key, const json& v) {
  if (!v.is_array()) Wrong(key, v, "an array of numbers");
  std::vector<double> out;
  for (const json& item : v) {
    if (!item.is_number()) Wrong(key, v, "an array of numbers");
    out.push_back(item.get<double>());
  }
  return out;
}
// A setting that takes "auto" or an integer (lags, hidden), held as its text: a string as given,
// an integer as its digits (Python's lags=8, a manifest's hidden = 20).
std::string AutoOrInteger(const char* key, const json& v) {
  if (v.is_number_integer()) return v.dump();
  if (!v.is_string()) Wrong(key, v, "auto or an integer");
  return v.get<std::string>();
}
double Number(const char* key, const json& v) {
  if (!v.is_number()) Wrong(key, v, "a number");
  return v.get<double>();
}
int Integer(const char* key, const json& v, int lo, int hi) {
  if (!v.is_number_integer() || v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi) {
    Wrong(key, v, ("an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]").c_str());
  }
  return v.get<int>();
}
bool Bool(const char* key, const json& v) {
  if (!v.is_boolean()) Wrong(key, v, "true or false");
  return v.get<bool>();
}
// An enum named by `text`, refused naming the key.
template <class Parse>
auto Enum(const char* key, const json& v, Parse parse) {
  const std::string text = String(key, v);
  try {
    return parse(text);
  } catch (const OptionError& e) {
    ThrowOption(key, "'" + text + "'", e.rule());
  }
}

using FS = drift::FitSettings;
const std::vector<Field<FS>>& FitFields() {
  static const std::vector<Field<FS>> kFields = {
      {"mode", [](const FS& s) { return json(s.mode); },
       [](const json& v, FS& s) { s.mode = String("mode", v); }},
      {"method", [](const FS& s) { return json(s.method); },
       [](const json& v, FS& s) { s.method = String("method", v); }},
      {"decomposition", [](const FS& s) { return json(s.decomposition); },
       [](const json& v, FS& s) { s.decomposition = String("decomposition", v); }},
      {"lags", [](const FS& s) { return json(s.lags); },
       [](const json& v, FS& s) { s.lags = AutoOrInteger("lags", v); }},
      {"hidden", [](const FS& s) { return json(s.hidden); },
       [](const json& v, FS& s) { s.hidden = AutoOrInteger("hidden", v); }},
      {"rate_hz", [](const FS& s) { return json(s.rate_hz); },
       [](const json& v, FS& s) { s.rate_hz = Number("rate_hz", v); }},
      {"thermal_features", [](const FS& s) { return json(s.thermal_features); },
       [](const json& v, FS& s) { s.thermal_features = String("thermal_features", v); }},
      {"time_constants", [](const FS& s) { return json(s.time_constants); },
       [](const json& v, FS& s) { s.time_constants = Numbers("time_constants", v); }},
      {"ensemble", [](const FS& s) { return json(s.ensemble); },
       [](const json& v, FS& s) { s.ensemble = Integer("ensemble", v, 1, 100000); }},
      {"realisations", [](const FS& s) { return json(s.realisations); },
       [](const json& v, FS& s) { s.realisations = Integer("realisations", v, 1, 1000000); }},
      {"seed", [](const FS& s) { return json(s.seed); },
       [](const json& v, FS& s) {
         if (!v.is_number_unsigned()) Wrong("seed", v, "a non-negative integer");
         s.seed = v.get<std::uint64_t>();
       }},
      {"threads", [](const FS& s) { return json(s.threads); },
       [](const json& v, FS& s) { s.threads = Integer("threads", v, 0, 1024); }},
      {"nonlinear", [](const FS& s) { return json(s.nonlinear); },
       [](const json& v, FS& s) { s.nonlinear = Bool("nonlinear", v); }},
      {"reference_temperature",
       [](const FS& s) { return s.reference_temperature ? json(*s.reference_temperature) : json(); },
       [](const json& v, FS& s) {
         s.reference_temperature =
             v.is_null() ? std::nullopt : std::optional<double>(Number("reference_temperature", v));
       }},
      {"hysteresis", [](const FS& s) { return json(s.hysteresis); },
       [](const json& v, FS& s) { s.hysteresis = String("hysteresis", v); }},
      {"standard_errors", [](const FS& s) { return json(s.standard_errors); },
       [](const json& v, FS& s) { s.standard_errors = Number("standard_errors", v); }},
      {"has_temperature", [](const FS& s) { return json(s.has_temperature); },
       [](const json& v, FS& s) { s.has_temperature = Bool("has_temperature", v); }},
  };
  return kFields;
}

using LO = io::LogOptions;
const std::vector<Field<LO>>& LogFields() {
  static const std::vector<Field<LO>> kFields = {
      {"gaps", [](const LO& o) { return json(io::ToString(o.gaps)); },
       [](const json& v, LO& o) { o.gaps = Enum("gaps", v, io::GapPolicyFromString); }},
      {"delimiter", [](const LO& o) { return json(io::ToString(o.delimiter)); },
       [](const json& v, LO& o) { o.delimiter = Enum("delimiter", v, io::DelimiterFromString); }},
      {"names", [](const LO& o) { return json(o.names); },
       [](const json& v, LO& o) { o.names = Strings("names", v); }},
      {"skip_rows", [](const LO& o) { return json(o.skip_rows); },
       [](const json& v, LO& o) { o.skip_rows = Integer("skip_rows", v, 0, 1000000); }},
      {"bad_lines", [](const LO& o) { return json(io::ToString(o.bad_lines)); },
       [](const json& v, LO& o) { o.bad_lines = Enum("bad_lines", v, io::BadLinesFromString); }},
      {"ulog_topic", [](const LO& o) { return json(o.ulog.topic); },
       [](const json& v, LO& o) { o.ulog.topic = String("ulog_topic", v); }},
      {"ulog_axes", [](const LO& o) { return json(o.ulog.axes); },
       [](const json& v, LO& o) { o.ulog.axes = Strings("ulog_axes", v); }},
      {"ulog_temperature", [](const LO& o) { return json(o.ulog.temperature); },
       [](const json& v, LO& o) { o.ulog.temperature = String("ulog_temperature", v); }},
      {"ulog_units", [](const LO& o) { return json(allan::ToString(o.ulog.units)); },
       [](const json& v, LO& o) {
         o.ulog.units = Enum("ulog_units", v, allan::RateUnitFromString);
       }},
      {"ulog_instance", [](const LO& o) { return json(o.ulog_instance); },
       [](const json& v, LO& o) {
         o.ulog_instance = Integer("ulog_instance", v, 0, io::kMaxUlogInstance);
       }},
  };
  return kFields;
}

template <class T>
json Write(const std::vector<Field<T>>& fields, const T& value) {
  json j = json::object();
  for (const Field<T>& f : fields) j[f.key] = f.write(value);
  return j;
}

template <class T>
std::vector<std::string> Read(const std::vector<Field<T>>& fields, const json& j, T* value) {
  std::vector<std::string> read;
  for (const Field<T>& f : fields) {
    const auto it = j.find(f.key);
    if (it == j.end()) continue;
    f.read(*it, *value);
    read.push_back(f.key);
  }
  return read;
}

}  // namespace

json FitSettingsToJson(const drift::FitSettings& s) { return Write(FitFields(), s); }
json LogOptionsToJson(const io::LogOptions& o) { return Write(LogFields(), o); }
json SettingsToJson(const drift::FitSettings& s, const io::LogOptions& o) {
  return {{"version", kSettingsJsonVersion}, {"fit", FitSettingsToJson(s)}, {"log", LogOptionsToJson(o)}};
}

std::vector<std::string> FitSettingsFromJson(const json& j, drift::FitSettings* s) {
  return Read(FitFields(), j, s);
}
std::vector<std::string> LogOptionsFromJson(const json& j, io::LogOptions* o) {
  return Read(LogFields(), j, o);
}

void SettingsFromJson(const json& j, const std::string& source, drift::FitSettings* s,
                      io::LogOptions* o) {
  if (!j.is_object() || !j.contains("version") || j["version"] != kSettingsJsonVersion) {
    throw UsageError(source + ": settings of version " +
                     (j.is_object() && j.contains("version") ? j["version"].dump() : "none") +
                     ", this version reads " + std::to_string(kSettingsJsonVersion));
  }
  for (const auto& [part, fields] : {std::pair{"fit", j.value("fit", json::object())},
                                     std::pair{"log", j.value("log", json::object())}}) {
    const std::vector<std::string> read =
        std::string(part) == "fit" ? FitSettingsFromJson(fields, s) : LogOptionsFromJson(fields, o);
    if (read.size() != fields.size()) {
      for (const auto& [key, value] : fields.items()) {
        if (std::find(read.begin(), read.end(), key) == read.end()) {
          throw UsageError(source + ": unknown setting " + std::string(part) + "." + key);
        }
      }
    }
  }
}

}  // namespace gyrodrift::tasks
