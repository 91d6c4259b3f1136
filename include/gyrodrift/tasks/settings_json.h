// The settings as JSON: one writer and one reader of the fit settings (drift::FitSettings) and
// the log settings (io::LogOptions), key = field name (the log's ULog conversion flattened as
// ulog_topic, ulog_axes, ulog_temperature, ulog_units). A fleet manifest takes the log settings
// and the fit settings as keys through this mapping, Python's DriftModel.fit and evaluate take
// the fit settings as keywords through it (python/src/bindings.h, FitSettingsOf), and a unit's
// fingerprint is the settings' JSON with its version (fleet/manifest.h), so a field added to
// either struct and to its entry here reaches the manifest, Python and the fingerprint at once.
//
//   {"version": 1, "fit": {"mode": "compensate", "method": "thermal", ...},
//    "log": {"gaps": "error", "delimiter": "auto", "names": [], "skip_rows": 0, ...}}
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/io/gyro_log.h"

namespace gyrodrift::tasks {

// Bumped when a key changes meaning (not when one is added: a reader fills a missing key with its
// default).
inline constexpr int kSettingsJsonVersion = 1;

// Every field (LogOptions: but gaps_name, how a front end spells the gaps setting).
nlohmann::json FitSettingsToJson(const drift::FitSettings& settings);
nlohmann::json LogOptionsToJson(const io::LogOptions& log);
// {"version", "fit", "log"}.
nlohmann::json SettingsToJson(const drift::FitSettings& settings, const io::LogOptions& log);

// The keys of `j` (an object) that name a field are read into *settings / *log, the others left
// as they are; returns the keys read. A value of the wrong type or out of its range throws
// OptionError naming the key (ranges the library checks later, such as a method name, are left to
// it).
std::vector<std::string> FitSettingsFromJson(const nlohmann::json& j, drift::FitSettings* settings);
std::vector<std::string> LogOptionsFromJson(const nlohmann::json& j, io::LogOptions* log);
// The reader of SettingsToJson: UsageError naming `source` for another version or an unknown key.
void SettingsFromJson(const nlohmann::json& j, const std::string& source,
                      drift::FitSettings* settings, io::LogOptions* log);

}  // namespace gyrodrift::tasks
