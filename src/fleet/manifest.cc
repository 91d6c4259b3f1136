#include "gyrodrift/fleet/manifest.h"

#include <fmt/core.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/tasks/settings_json.h"

namespace gyrodrift::fleet {
namespace {

namespace fs = std::filesystem;

// Every message names the manifest and the line of the offending key or value.
class Context {
 public:
  explicit Context(std::string path) : path_(std::move(path)) {}
  [[noreturn]] void Fail(int line, const std::string& what) const {
    throw UsageError(fmt::format("{}:{}: {}", path_, line, what));
  }
  [[noreturn]] void Fail(const toml::node& node, const std::string& what) const {
    Fail(static_cast<int>(node.source().begin.line), what);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

const char* TypeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "true/false";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date or time";
  }
}

// A table whose keys must come from `known`; lookups name the key's line.
class Table {
 public:
  Table(const toml::table& t, const Context& c, std::string where, std::set<std::string> known)
      : t_(t), c_(c), where_(std::move(where)) {
    for (auto&& [key, value] : t_) {
      if (known.count(std::string(key.str())) == 0) {
        c_.Fail(value, fmt::format("unknown key '{}'{} (known: {})", key.str(), where_,
                                   Join(known)));
      }
    }
  }
  const toml::node* Find(const std::string& key) const { return t_.get(key); }
  int line() const { return static_cast<int>(t_.source().begin.line); }

  std::string String(const std::string& key) const {
    const toml::node* n = Require(key);
    if (!n->is_string()) c_.Fail(*n, fmt::format("'{}' must be a string, not {}", key, TypeName(*n)));
    const std::string s = *n->value<std::string>();
    if (s.empty()) c_.Fail(*n, fmt::format("'{}' is empty", key));
    return s;
  }
  std::string String(const std::string& key, const std::string& fallback) const {
    return Find(key) ? String(key) : fallback;
  }
  double Number(const std::string& key, double fallback, double lo, double hi) const {
    const toml::node* n = Find(key);
    if (!n) return fallback;
    if (!n->is_number()) c_.Fail(*n, fmt::format("'{}' must be a number, not {}", key, TypeName(*n)));
    const double v = *n->value<double>();
    if (!(v >= lo && v <= hi)) {
      c_.Fail(*n, fmt::format("'{}' = {}: must be in [{}, {}]", key, v, lo, hi));
    }
    return v;
  }
  // The value of a string key that names an enum, parsed by `parse` (a FromString helper); a
  // refusal names the key: "key = 'text': must be one of ...".
  template <class Parse>
  auto Enum(const std::string& key, Parse parse) const {
    const std::string text = String(key);
    try {
      return parse(text);
    } catch (const OptionError& e) {
      c_.Fail(*Find(key), fmt::format("{} = '{}': must be {}", key, text, e.rule()));
    }
  }
  bool Bool(const std::string& key, bool fallback) const {
    const toml::node* n = Find(key);
    if (!n) return fallback;
    if (!n->is_boolean()) c_.Fail(*n, fmt::format("'{}' must be true or false, not {}", key, TypeName(*n)));
    return *n->value<bool>();
  }
  // A string or an array of non-empty strings, at least one.
  std::vector<std::string> Strings(const std::string& key) const {
    const toml::node* n = Require(key);
    std::vector<std::string> out;
    if (n->is_string()) {
      out.push_back(*n->value<std::string>());
    } else if (const toml::array* a = n->as_array()) {
      for (const toml::node& item : *a) {
        if (!item.is_string()) {
          c_.Fail(item, fmt::format("'{}' must hold strings, not {}", key, TypeName(item)));
        }
        out.push_back(*item.value<std::string>());
      }
    } else {
      c_.Fail(*n, fmt::format("'{}' must be a string or an array of strings, not {}", key,
                              TypeName(*n)));
    }
    if (out.empty()) c_.Fail(*n, fmt::format("'{}' is empty", key));
    for (size_t i = 0; i < out.size(); ++i) {
      if (out[i].empty()) c_.Fail(*n, fmt::format("'{}' holds an empty name", key));
      if (std::find(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(i), out[i]) !=
          out.begin() + static_cast<std::ptrdiff_t>(i)) {
        c_.Fail(*n, fmt::format("'{}' names '{}' twice", key, out[i]));
      }
    }
    return out;
  }
  const toml::node* Require(const std::string& key) const {
    const toml::node* n = Find(key);
    if (!n) c_.Fail(line(), fmt::format("'{}' is missing{}", key, where_));
    return n;
  }

 private:
  static std::string Join(const std::set<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  }
  const toml::table& t_;
  const Context& c_;
  std::string where_;
};

// An array of tables ([[axis]], [[unit]]).
std::vector<const toml::table*> TableArray(const toml::table& root, const std::string& key,
                                           const Context& c) {
  const toml::node* n = root.get(key);
  if (!n) c.Fail(1, fmt::format("no [[{}]] table: the manifest needs at least one", key));
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables()) {
    c.Fail(*n, fmt::format("'{}' must be an array of tables ([[{}]])", key, key));
  }
  std::vector<const toml::table*> out;
  for (const toml::node& item : *a) out.push_back(item.as_table());
  return out;
}

std::string Resolve(const std::string& manifest, const std::string& log) {
  const fs::path p(log);
  if (p.is_absolute()) return log;
  return (fs::path(manifest).parent_path() / p).lexically_normal().string();
}

}  // namespace

std::vector<std::string> UnitSpec::Logs() const {
  std::vector<std::string> logs = calibration;
  logs.insert(logs.end(), verification.begin(), verification.end());
  return logs;
}

drift::DriftOptions Manifest::FitOptions() const { return drift::MakeDriftOptions(fit); }

drift::Method Manifest::FitMethod() const {
  return drift::ResolveMethod(fit.method, drift::Mode::kCompensate);
}

namespace {

// A TOML value as JSON (strings, numbers, booleans and arrays of them), for the settings' reader
// (a non-negative integer as unsigned, which the reader takes for a seed).
nlohmann::json ToJson(const toml::node& n) {
  if (n.is_string()) return *n.value<std::string>();
  if (n.is_integer()) {
    const std::int64_t v = *n.value<std::int64_t>();
    return v >= 0 ? nlohmann::json(static_cast<std::uint64_t>(v)) : nlohmann::json(v);
  }
  if (n.is_floating_point()) return *n.value<double>();
  if (n.is_boolean()) return *n.value<bool>();
  nlohmann::json out = nlohmann::json::array();
  if (const toml::array* a = n.as_array()) {
    for (const toml::node& item : *a) out.push_back(ToJson(item));
  }
  return out;
}

// The manifest's key of the fit setting `setting` (drift::FitSettings), "" for those the fleet
// sets: mode (compensate), has_temperature (the axes' columns), threads (calibrate --threads:
// how it runs) and rate_hz (the fleet's own key, 0 = from each log). reference_temperature keeps
// the spelling with its unit that manifests have always used.
std::string FitKey(const std::string& setting) {
  if (setting == "mode" || setting == "has_temperature" || setting == "threads" ||
      setting == "rate_hz") {
    return "";
  }
  return setting == "reference_temperature" ? "reference_temperature_c" : setting;
}

// The manifest's top-level keys: the fleet's, every fit setting's (FitKey) and every log
// setting's (tasks::LogOptionsToJson's keys).
std::set<std::string> TopKeys() {
  std::set<std::string> keys = {"rate_unit", "rate_hz", "drift_window_s", "limits", "axis", "unit"};
  // Named first: items() of a temporary would outlive it.
  const nlohmann::json fit = tasks::FitSettingsToJson({}), log = tasks::LogOptionsToJson({});
  for (const auto& [setting, value] : fit.items()) {
    if (!FitKey(setting).empty()) keys.insert(FitKey(setting));
  }
  for (const auto& [key, value] : log.items()) keys.insert(key);
  return keys;
}

// The log settings, read through their one mapping (tasks::LogOptionsFromJson); a refusal is
// placed at its key.
void ReadLogKeys(const Table& top, const Context& c, Manifest& m) {
  nlohmann::json keys = nlohmann::json::object();
  const nlohmann::json log = tasks::LogOptionsToJson({});
  for (const auto& [key, value] : log.items()) {
    if (const toml::node* n = top.Find(key)) keys[key] = ToJson(*n);
  }
  try {
    tasks::LogOptionsFromJson(keys, &m.log);
  } catch (const OptionError& e) {
    c.Fail(*top.Find(e.option()), e.what());
  }
  if (const toml::node* n = top.Find("gaps")) {
    if (m.log.gaps == io::GapPolicy::kSplit && m.FitMethod() != drift::Method::kThermal) {
      c.Fail(*n, fmt::format("gaps = 'split' needs method = 'thermal', not '{}' (a "
                             "decomposition would run across the gaps)",
                             drift::ToString(m.FitMethod())));
    }
    if (m.log.gaps == io::GapPolicy::kCarry && drift::UsesDecomposition(m.FitMethod())) {
      c.Fail(*n, fmt::format("gaps = 'carry' needs a method that fits on the logged "
                             "rows only (thermal or poly), not '{}' (a "
                             "decomposition would run across the made-up rows)",
                             drift::ToString(m.FitMethod())));
    }
  }
}

// The fit settings, read through their one mapping (tasks::FitSettingsFromJson) and checked
// together as fit's flags are (drift::MakeDriftOptions); a refusal is placed at the key it names.
void ReadFitKeys(const Table& top, const Context& c, Manifest& m) {
  nlohmann::json keys = nlohmann::json::object();
  const nlohmann::json settings = tasks::FitSettingsToJson({});
  for (const auto& [setting, value] : settings.items()) {
    const std::string key = FitKey(setting);
    if (!key.empty() && top.Find(key)) keys[setting] = ToJson(*top.Find(key));
  }
  try {
    tasks::FitSettingsFromJson(keys, &m.fit);
    if (!drift::SupportsMode(m.FitMethod(), drift::Mode::kCompensate)) {
      c.Fail(*top.Find("method"),
             fmt::format("method = '{}' does not compensate", drift::ToString(m.FitMethod())));
    }
    (void)m.FitOptions();
  } catch (const OptionError& e) {
    const std::string key = FitKey(e.option()).empty() ? e.option() : FitKey(e.option());
    const std::string message = fmt::format("{} = {}: must be {}", key, e.value(), e.rule());
    if (const toml::node* n = top.Find(key)) c.Fail(*n, message);
    c.Fail(top.line(), message);
  }
}

void ReadLimits(const Table& top, const Context& c, Manifest& m) {
  if (const toml::node* n = top.Find("limits")) {
    if (!n->is_table()) c.Fail(*n, "'limits' must be a table ([limits])");
    const Table limits(*n->as_table(), c, " in [limits]",
                       {"residual_drift_rms", "bias_instability_dph", "removed_share_min"});
    m.limits.residual_drift_rms = limits.Number("residual_drift_rms", kNoLimit, 0.0, 1e12);
    m.limits.bias_instability_dph = limits.Number("bias_instability_dph", kNoLimit, 0.0, 1e12);
    m.limits.removed_share_min = limits.Number("removed_share_min", kNoLimit, 0.0, 1.0);
  }

}

void ReadAxes(const toml::table& root, const Context& c, Manifest& m) {
  for (const toml::table* t : TableArray(root, "axis", c)) {
    const Table axis(*t, c, " in [[axis]]", {"target", "temperature", "truth"});
    AxisSpec a;
    a.line = axis.line();
    a.target = axis.String("target");
    a.temperature = axis.Strings("temperature");
    a.truth = axis.Find("truth") ? axis.String("truth") : "";
    for (const AxisSpec& earlier : m.axes) {
      if (earlier.target == a.target) {
        c.Fail(a.line, fmt::format("axis target '{}' repeats the axis of line {}", a.target,
                                   earlier.line));
      }
    }
    for (const std::string& t_col : a.temperature) {
      if (t_col == a.target || t_col == a.truth) {
        c.Fail(a.line, fmt::format("column '{}' is both the target or truth and a temperature", t_col));
      }
    }
    if (!a.truth.empty() && a.truth == a.target) {
      c.Fail(a.line, fmt::format("truth '{}' is the target column", a.truth));
    }
    m.axes.push_back(std::move(a));
  }
  if (static_cast<int>(m.axes.size()) > io::kMaxModelAxes) {
    c.Fail(m.axes.back().line, fmt::format("{} axes: a model file holds at most {}",
                                           m.axes.size(), io::kMaxModelAxes));
  }
  if (!std::isnan(m.limits.removed_share_min)) {
    for (const AxisSpec& a : m.axes) {
      if (a.truth.empty()) {
        c.Fail(a.line, fmt::format("limits.removed_share_min needs the true drift: axis '{}' has "
                                   "no 'truth' column", a.target));
      }
    }
  }

}

void ReadUnits(const toml::table& root, const Context& c, const std::string& path, Manifest& m) {
  for (const toml::table* t : TableArray(root, "unit", c)) {
    const Table unit(*t, c, " in [[unit]]", {"serial", "calibration", "verification"});
    UnitSpec u;
    u.line = unit.line();
    u.serial = unit.String("serial");
    // The serial names the unit's output folder: no path separators, no "." or "..", not the
    // name of a fleet-level file (case aside: some file systems ignore it).
    std::string lower = u.serial;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    if (u.serial.find_first_of(std::string("\0\n\r\t", 4)) != std::string::npos) {
      // Not printed: a NUL would cut the message short.
      c.Fail(u.line,
             "serial holds a control character (NUL, tab or line break): it names a folder");
    }
    if (u.serial == "." || u.serial == ".." ||
        u.serial.find_first_of("/\\:*?\"<>|") != std::string::npos) {
      c.Fail(u.line, fmt::format("serial '{}' must be usable as a folder name (no / \\ : * ? \" "
                                 "< > |)", u.serial));
    }
    if (lower == kFleetTableFile || lower == kFleetReportFile) {
      c.Fail(u.line, fmt::format("serial '{}' is the name of a file the fleet writes beside the "
                                 "units' folders: choose another",
                                 u.serial));
    }
    for (const UnitSpec& earlier : m.units) {
      if (earlier.serial == u.serial) {
        c.Fail(u.line, fmt::format("serial '{}' repeats the unit of line {}", u.serial,
                                   earlier.line));
      }
    }
    for (const std::string& log : unit.Strings("calibration")) {
      u.calibration.push_back(Resolve(path, log));
      u.calibration_as_written.push_back(log);
    }
    if (u.calibration.size() > 1 && m.FitMethod() != drift::Method::kThermal) {
      c.Fail(*unit.Find("calibration"),
             fmt::format("several calibration logs need method = 'thermal', not '{}' (its thermal "
                         "states restart with each log; a decomposition would run across them)",
                         drift::ToString(m.FitMethod())));
    }
    for (const std::string& v : unit.Strings("verification")) {
      u.verification.push_back(Resolve(path, v));
    }
    for (const std::string& log : u.Logs()) {
      std::error_code ec;
      if (!fs::is_regular_file(log, ec)) {
        c.Fail(u.line, fmt::format("unit '{}': log {} does not exist", u.serial, log));
      }
    }
    m.units.push_back(std::move(u));
  }
}

}  // namespace

Manifest ParseManifest(const std::string& text, const std::string& path) {
  const Context c(path);
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    c.Fail(static_cast<int>(e.source().begin.line),
           fmt::format("not valid TOML: {}", e.description()));
  }
  Manifest m;
  m.path = path;
  const Table top(root, c, "", TopKeys());
  ReadFitKeys(top, c, m);
  if (top.Find("rate_unit")) m.rate_unit = top.Enum("rate_unit", allan::RateUnitFromString);
  m.rate_hz = top.Number("rate_hz", 0.0, 1e-9, 1e6);
  ReadLogKeys(top, c, m);
  m.drift_window_s = top.Number("drift_window_s", m.drift_window_s, 1.0, 1e5);
  ReadLimits(top, c, m);
  ReadAxes(root, c, m);
  ReadUnits(root, c, path, m);
  return m;
}

Manifest ReadManifest(const std::string& path) { return ParseManifest(io::ReadTextFile(path), path); }

namespace {

// The column names of a log as the log settings read it: the names given for a file without a
// header row (a serial capture), else its header row, parsed by the CSV reader from the log's
// first lines after skip_rows up to its first data row (comments and blank lines included), so the
// whole file need not be read. A ULog's columns are those `convert` writes (time_s, one per axis
// and temperature_c): io::ReadLog checks its series when the unit is calibrated, so nothing is
// read here (empty: not checked).
std::vector<std::string> Header(const std::string& log, const io::LogOptions& options) {
  if (!options.names.empty() || io::IsUlogFile(log)) return options.names;
  std::ifstream in(log, std::ios::binary);
  if (!in) throw IoError(log + ": cannot be read");
  std::string text, line;
  int rows = 0, skipped = 0;
  while (rows < 2 && std::getline(in, line)) {
    if (skipped < options.skip_rows) {
      ++skipped;
      continue;
    }
    text += line + "\n";
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') ++rows;
  }
  return io::CsvTable::Parse(text, log, options.delimiter).header();
}

}  // namespace

void CheckLogColumns(const Manifest& m) {
  const Context c(m.path);
  for (const UnitSpec& u : m.units) {
    const std::vector<std::string> logs = u.Logs();
    for (size_t k = 0; k < logs.size(); ++k) {
      std::vector<std::string> header;
      try {
        header = Header(logs[k], m.log);
      } catch (const Error& e) {
        c.Fail(u.line, fmt::format("unit '{}': {}", u.serial, e.what()));
      }
      if (header.empty()) continue;  // a ULog: checked when read
      auto has = [&](const std::string& name) {
        return std::find(header.begin(), header.end(), name) != header.end();
      };
      for (const AxisSpec& a : m.axes) {
        std::vector<std::string> needed = a.temperature;
        needed.insert(needed.begin(), a.target);
        if (k >= u.calibration.size() && !a.truth.empty()) needed.push_back(a.truth);
        for (const std::string& col : needed) {
          if (!has(col)) {
            c.Fail(u.line, fmt::format("unit '{}': {} has no column '{}' (axis of line {})",
                                       u.serial, logs[k], col, a.line));
          }
        }
      }
    }
  }
}

std::string PathFromManifest(const Manifest& m, const std::string& log) {
  std::error_code folder_error, log_error;
  const fs::path folder = fs::absolute(m.path, folder_error).parent_path();
  const fs::path absolute = fs::absolute(log, log_error).lexically_normal();
  if (folder_error || log_error) return log;
  const fs::path relative = absolute.lexically_relative(folder);
  return (relative.empty() ? absolute : relative).string();
}

nlohmann::json FingerprintJson(const Manifest& m, const UnitSpec& u) {
  nlohmann::json axes = nlohmann::json::array();
  for (const AxisSpec& a : m.axes) {
    axes.push_back({{"target", a.target}, {"temperature", a.temperature}, {"truth", a.truth}});
  }
  // NaN (a limit not set) as null.
  auto limit = [](double v) { return std::isnan(v) ? nlohmann::json() : nlohmann::json(v); };
  // Each log by its path from the manifest's folder: the same however the manifest was named and
  // from whichever folder or front end the run started (a rerun from elsewhere redid every unit),
  // and when the whole tree moves.
  nlohmann::json logs = nlohmann::json::array();
  for (const std::string& log : u.Logs()) {
    logs.push_back({{"path", PathFromManifest(m, log)},
                    {"fnv1a64", fmt::format("{:016x}", io::Fnv1a64(io::ReadTextFile(log)))}});
  }
  // Raised when a unit's files change for the same logs and settings, so that a rerun redoes the
  // units an older tool finished (2: 2026-11-27, unidentified noise terms empty, model.json's
  // source as the manifest spells it, epoch time stamps' rate, a copied verification refused;
  // 3: 2026-11-28, a verification log named by its path from the manifest's folder).
  constexpr int kResultsVersion = 3;
  return {
      {"results_version", kResultsVersion},
      {"settings", tasks::SettingsToJson(m.fit, m.log)},
      {"fleet",
       {{"rate_unit", allan::ToString(m.rate_unit)},
        {"rate_hz", m.rate_hz},
        {"drift_window_s", m.drift_window_s},
        {"limits",
         {{"residual_drift_rms", limit(m.limits.residual_drift_rms)},
          {"bias_instability_dph", limit(m.limits.bias_instability_dph)},
          {"removed_share_min", limit(m.limits.removed_share_min)}}},
        {"axes", axes}}},
      {"unit", {{"serial", u.serial}, {"calibration_logs", u.calibration.size()}, {"logs", logs}}}};
}

std::string UnitFingerprint(const Manifest& m, const UnitSpec& u) {
  return fmt::format("fnv1a64:{:016x}", io::Fnv1a64(FingerprintJson(m, u).dump()));
}

}  // namespace gyrodrift::fleet
