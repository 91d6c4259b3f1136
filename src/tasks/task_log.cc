#include "gyrodrift/tasks/task_log.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "gyrodrift/common/check.h"
#include "gyrodrift/drift/temperature_check.h"

namespace gyrodrift::tasks {

TaskLog ReadTaskLog(const std::string& path, const io::LogOptions& log) {
  TaskLog t;
  t.path = path;
  t.table = io::ReadLog(path, log, &t.gap_note, &t.record_starts, {}, &t.logged);
  t.time_note = io::NonUniformTimeNote(t.table);
  return t;
}

TaskLog ReadTaskLog(const std::string& path, const io::LogOptions& log, double rate_hz_given) {
  TaskLog t = ReadTaskLog(path, log);
  t.rate_hz = io::ResolveSampleRate(t.table, rate_hz_given, &t.rate_how);
  return t;
}

bool SpeltAsFlags(const io::LogOptions& log) { return log.gaps_name.rfind("--", 0) == 0; }

std::string RateSourceText(const std::string& how, bool flags) {
  const std::string rate = flags ? "--rate-hz" : "rate_hz";
  return how == "given"    ? "given by " + rate
         : how == "time_s" ? "from the steps of time_s"
                           : "assumed: no " + rate + " and no time_s column";
}

void RequireRateOfModel(const std::string& log_path, double log_hz, const std::string& how,
                        bool flags, const std::string& model_path, double model_hz,
                        const std::function<std::string(double ratio)>& effect) {
  const double ratio = log_hz / model_hz;
  if (how == "default" || std::abs(ratio - 1.0) <= 0.01) return;
  throw DataError(fmt::format(
      "{} is sampled at {:g} Hz ({}), {} was fitted at {:g} Hz: {} (resample the log to {:g} Hz "
      "or fit the model on a log at {:g} Hz{})",
      log_path, log_hz, RateSourceText(how, flags), model_path, model_hz, effect(ratio), model_hz,
      log_hz,
      how == "time_s" ? fmt::format("; give {} if time_s is wrong", flags ? "--rate-hz" : "rate_hz")
                      : ""));
}

std::vector<std::string> SplitColumns(const std::string& names) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= names.size()) {
    const size_t comma = names.find(',', start);
    out.push_back(names.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

SelectedColumns ReadColumns(const io::CsvTable& table, const std::string& spec,
                            const std::string& option) {
  const std::vector<std::string> items = SplitColumns(spec);
  SelectedColumns out;
  out.values.resize(0, static_cast<Eigen::Index>(items.size()));
  std::vector<std::string> seen;
  for (size_t c = 0; c < items.size(); ++c) {
    if (items[c].empty()) ThrowOption(option, "'" + spec + "'", "column names without empty items");
    const std::string name = table.header()[static_cast<size_t>(table.ResolveColumn(items[c]))];
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      ThrowOption(option, "'" + spec + "'", "a list without repeats");
    }
    seen.push_back(name);
    const Eigen::VectorXd column = table.Column(items[c]);
    if (c == 0) out.values.resize(column.size(), static_cast<Eigen::Index>(items.size()));
    out.values.col(static_cast<Eigen::Index>(c)) = column;
    out.joined += (c ? "," : "") + name;
    out.names.push_back(name);
  }
  return out;
}

std::vector<std::string> LogWarnings(const TaskLog& log, const std::string& rate_how,
                                     const std::vector<std::string>& temperature_columns,
                                     Audience audience) {
  std::vector<std::string> out;
  // A manifest's table names its file only; flags and keywords name the path as given.
  const bool manifest = audience == Audience::kManifest;
  const std::string name =
      manifest ? std::filesystem::path(log.path).filename().string() : log.path;
  if (rate_how == "default") {
    out.push_back(manifest
                      ? name +
                            ": no time_s column: its sample rate is taken as 1 Hz (set "
                            "rate_hz in the manifest if it is not)"
                      : fmt::format("{} has no time_s column: its sample rate is taken as 1 "
                                    "Hz (give {} if it is not)",
                                    name, audience == Audience::kFlags ? "--rate-hz" : "rate_hz="));
  }
  for (const std::string& column : temperature_columns) {
    const std::string w = drift::TemperatureWarning(log.table.Column(column), column);
    if (!w.empty()) out.push_back(name + ": " + w);
  }
  return out;
}

}  // namespace gyrodrift::tasks
