// Helpers shared by the subcommands: loading a column, options common to several commands,
// JSON sidecars. Kept here so every subcommand reports errors the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/gyro_log.h"

namespace gyrodrift::cli {

// CLI11 validator: the value must name an existing regular file (message: "FILE: no such file").
extern const CLI::Validator kInputFile;

// CLI11 validator for --seed: an integer in [0, 2^64). CLI11 2.1 would silently wrap "-1" to
// 2^64 - 1 and clamp values that overflow.
extern const CLI::Validator kSeed;

// The sidecar path of an output file: OUT.csv -> OUT.csv.json.
std::string SidecarPath(const std::string& output_path);

// The guards of the user's log (io/files.h).
using io::RequireOutputsAreNotInputs;

// Common metadata of every sidecar: tool name, version and subcommand.
nlohmann::json SidecarHeader(const std::string& command);

// True when stderr (where progress goes) is a terminal and progress may be shown.
bool IsTerminal();

// --duration text: "30s", "10min", "8h", "1.5h", "3600" (seconds), "1e4s". Anything else, or a
// value that is not positive and finite, is a UsageError naming --duration.
double ParseDuration(const std::string& text);

// The log rules every command shares (io/gyro_log.h).
using io::NonUniformTimeNote;
using io::ReadLog;
using io::ResolveSampleRate;

// How a command reads its log: --gaps (io::GapPolicy) and --delimiter (io::Delimiter).
struct LogArgs {
  std::string gaps = "error";
  std::string delimiter = "auto";
  // A serial capture: --no-header --columns a,b,c, --skip-rows N, --bad-lines error|skip.
  bool no_header = false;
  std::vector<std::string> columns;
  int skip_rows = io::CsvReadOptions{}.skip_rows;
  std::string bad_lines{io::ToString(io::CsvReadOptions{}.bad_lines)};
  // A PX4 ULog read directly: --ulog-topic, --ulog-instance, --ulog-units (io::LogOptions::ulog).
  io::UlogConversion ulog;
  int ulog_instance = io::LogOptions{}.ulog_instance;
  std::string ulog_units{allan::ToString(io::UlogConversion{}.units)};
  // Messages spell the settings as the flags (--gaps); UsageError for --columns without
  // --no-header or the other way round.
  io::LogOptions Options() const;
  bool Given() const { return Options() != io::LogOptions{.gaps_name = "--gaps"}; }
  // A command that analyses one uniform record (`who`, e.g. "decompose") refuses --gaps split
  // and carry with a one-line UsageError saying `why`.
  void RequireOneRecord(std::string_view who, std::string_view why) const;
};
// --gaps error|interpolate|split|carry (every command takes the same modes; one that cannot
// honour split or carry refuses it, LogArgs::RequireOneRecord),
// --delimiter auto|comma|tab|semicolon, the serial-capture flags and the ULog selection of
// LogArgs.
void AddLogOptions(CLI::App* cmd, LogArgs* log);
// ReadLog under those choices; the note on filled or split gaps, if any, is appended (with a
// newline) to *notes; record_starts, columns (the only ones kept, with time_s; empty = all) and
// logged as io::ReadLog's.
io::CsvTable ReadLog(const std::string& path, const LogArgs& log, std::string* notes,
                     std::vector<Eigen::Index>* record_starts = nullptr,
                     const std::vector<std::string>& columns = {},
                     std::vector<bool>* logged = nullptr);

// Predict mode on a log whose gaps --gaps interpolate filled (`logged`: false on a made-up row):
// the note that the predictions of the made-up rows, and the first after each gap, read the
// logged sample after the gap, so they are not causal; "" for a log without made-up rows.
std::string MadeUpRowsPredictionNote(const std::vector<bool>& logged);

// Refuses an empty value for every numeric option and every --output of app's subcommands: CLI11
// reads '' (an unset shell variable) as 0, which would set a reference temperature of 0 degC
// without a word, and an empty output name would fail only after the work, as a file error. An
// --output of '-' is refused too: it would be a file named '-', not standard output.
void RefuseEmptyValues(CLI::App& app);

// Declares a list flag: values comma-separated ("60,300,900"), space-separated or the flag
// repeated, each converted as CLI11 converts a T. An empty item ("60,,300", "60,") is refused:
// CLI11's own splitting (Option::delimiter) drops it without a word (its bracket form "[60,,300]"
// still does, before this sees the value). The default shown in --help is `values` as declared.
template <typename T>
CLI::Option* AddListOption(CLI::App* cmd, const std::string& name, std::vector<T>* values,
                           const std::string& help) {
  std::string shown;
  for (const T& v : *values) shown += (shown.empty() ? "" : ",") + CLI::detail::to_string(v);
  CLI::Option* option = cmd->add_option_function<std::vector<std::string>>(
      name,
      [values, name](const std::vector<std::string>& tokens) {
        values->clear();
        for (const std::string& token : tokens) {
          if (token.empty()) throw CLI::ValidationError(name + ": an empty value is not a list");
          for (size_t begin = 0, end = 0; begin <= token.size(); begin = end + 1) {
            end = std::min(token.find(',', begin), token.size());
            const std::string item = token.substr(begin, end - begin);
            T value{};
            if (item.empty()) {
              throw CLI::ValidationError(name + " = " + token + ": an empty item in the list");
            }
            if (!CLI::detail::lexical_cast(item, value)) {
              std::string kind = "a value";
              if constexpr (std::is_floating_point_v<T>) kind = "a number";
              if constexpr (std::is_integral_v<T>) {
                kind = "an integer in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
                       std::to_string(std::numeric_limits<T>::max()) + "]";
              }
              throw CLI::ValidationError(name + " = " + token + ": '" + item + "' is not " + kind);
            }
            values->push_back(std::move(value));
          }
        }
      },
      help);
  option->type_name(CLI::detail::type_name<T>());
  if (!shown.empty()) option->default_str(shown);
  return option;
}

// The message of CLI11's "Could not convert: --flag = value" with what a numeric flag takes
// ("--ensemble = 1e3: must be an integer (write 1000)", "... = 99999999999: out of range");
// CLI11's own message for other flags (on/off, text) and when the flag is not found.
std::string ConversionMessage(const CLI::App& app, const CLI::ConversionError& error);

// Binds `flag` to the names under which the library refers to what it sets (a
// drift::FitSettings setting such as "lags", an options field such as "ensemble_size"), where
// the flag is declared: an OptionError naming one of them is then reported with the flag.
// Returns `flag`.
CLI::Option* BindSetting(CLI::Option* flag, std::initializer_list<std::string_view> names);

// The one-line message for an option error: the library names its field or setting
// (`ensemble_size = 0: must be ...`); when the user gave a flag bound to that name, the message
// names the flag instead (`--ensemble = 0: must be ...`).
std::string OptionErrorMessage(const OptionError& error);

// Header name of a column spec (name or 1-based index). Throws UsageError like CsvTable.
std::string ColumnName(const io::CsvTable& table, const std::string& spec);

}  // namespace gyrodrift::cli
