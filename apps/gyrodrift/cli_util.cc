#include "cli_util.h"

#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <regex>
#include <sstream>
#include <vector>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/version.h"

namespace gyrodrift::cli {

const CLI::Validator kInputFile(
    [](std::string& path) -> std::string {
      struct stat st {};
      if (::stat(path.c_str(), &st) != 0) return path + ": no such file";
      if (!S_ISREG(st.st_mode)) return path + ": not a regular file";
      return {};
    },
    "FILE");

const CLI::Validator kSeed(
    [](std::string& text) -> std::string {
      std::uint64_t value = 0;
      const char* end = text.data() + text.size();
      const auto [ptr, ec] = std::from_chars(text.data(), end, value);
      const bool ok = !text.empty() && ec == std::errc() && ptr == end;
      return ok ? std::string() : text + ": must be an integer in [0, 2^64)";
    },
    "SEED");

std::string SidecarPath(const std::string& output_path) { return output_path + ".json"; }

nlohmann::json SidecarHeader(const std::string& command) {
  return {{"tool", "gyrodrift"}, {"version", kVersion}, {"command", command}};
}

bool IsTerminal() { return ::isatty(STDERR_FILENO) != 0; }

namespace {

// Every binding of BindSetting: a name and the flag that sets it.
std::vector<std::pair<std::string, const CLI::Option*>>& Bindings() {
  static std::vector<std::pair<std::string, const CLI::Option*>> bindings;
  return bindings;
}

}  // namespace

void RefuseEmptyValues(CLI::App& app) {
  const CLI::Validator not_a_number(
      [](std::string& value) {
        return value.empty() ? std::string("an empty value is not a number") : std::string();
      },
      "", "NOT_EMPTY");
  const CLI::Validator not_a_path(
      [](std::string& value) {
        if (value.empty()) return std::string("an empty value is not a path");
        // Outputs are written whole and renamed into place: a stream cannot take them.
        if (value == "-") return std::string("'-' (standard output) is not supported: name a file");
        return std::string();
      },
      "", "OUTPUT_PATH");
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* option : sub->get_options()) {
      const std::string type = option->get_type_name();
      if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0 || type.rfind("FLOAT", 0) == 0) {
        option->check(not_a_number);
      } else if (option->check_lname("output")) {
        option->check(not_a_path);
      }
    }
    RefuseEmptyValues(*sub);
  }
}

std::string ConversionMessage(const CLI::App& app, const CLI::ConversionError& error) {
  static const std::regex kConvert("Could not convert: (\\S+) = (.*)");
  std::smatch m;
  const std::string what = error.what();
  if (!std::regex_match(what, m, kConvert)) return what;
  const std::string name = m[1], value = m[2];
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* option : sub->get_options()) {
      if (!option->check_name(name)) continue;
      const std::string type = option->get_type_name();
      if (type.rfind("FLOAT", 0) == 0) return name + " = " + value + ": must be a number";
      if (type.rfind("INT", 0) != 0 && type.rfind("UINT", 0) != 0) return what;  // on/off, text
      // "1e3" is a number CLI11 does not read as an integer: say which integer it is. An integer
      // written as one but refused is beyond the flag's type.
      double number = 0.0;
      const char* end = value.data() + value.size();
      const auto [ptr, ec] = std::from_chars(value.data(), end, number);
      const bool whole = ec == std::errc() && ptr == end && std::isfinite(number) &&
                         number == std::trunc(number) && std::abs(number) < 9.0e15;
      const bool written_whole =
          whole && value.find_first_not_of("+-0123456789") == std::string::npos;
      if (written_whole) return name + " = " + value + ": out of range";
      return name + " = " + value + ": must be an integer" +
             (whole ? fmt::format(" (write {})", static_cast<long long>(number)) : "");
    }
  }
  return what;
}

CLI::Option* BindSetting(CLI::Option* flag, std::initializer_list<std::string_view> names) {
  for (std::string_view name : names) Bindings().emplace_back(name, flag);
  return flag;
}

std::string OptionErrorMessage(const OptionError& error) {
  // Only a flag the user gave: a value the command derived (a rate read from time_s, a duration
  // from a profile file) keeps the library's name rather than blaming a flag nobody typed. A
  // setting missing ("none") is named by the flag that gives it.
  for (const auto& [name, flag] : Bindings()) {
    if (name == error.option() && (flag->count() > 0 || error.value() == "none")) {
      const std::string shown = flag->get_lnames().empty() ? "-" + flag->get_snames().front()
                                                           : "--" + flag->get_lnames().front();
      return shown + " = " + error.value() + ": must be " + error.rule();
    }
  }
  return error.what();
}

std::string ColumnName(const io::CsvTable& table, const std::string& spec) {
  return table.header()[static_cast<size_t>(table.ResolveColumn(spec))];
}

double ParseDuration(const std::string& text) {
  static const std::regex kPattern(
      R"(^\s*([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?\s*(s|min|h)?\s*$)");
  std::smatch m;
  if (std::regex_match(text, m, kPattern)) {
    const std::string number = m[1].str() + m[3].str();
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
    const std::string unit = m[4].str();
    const double seconds = unit == "h" ? value * 3600.0 : unit == "min" ? value * 60.0 : value;
    if (ec == std::errc() && seconds > 0.0 && std::isfinite(seconds)) return seconds;
  }
  ThrowOption("--duration", text, "a positive duration such as 30s, 10min, 8h or plain seconds");
}

io::LogOptions LogArgs::Options() const {
  if (no_header != !columns.empty()) {
    throw UsageError(no_header ? "--no-header needs --columns naming the file's columns in order"
                               : "--columns names the columns of a file without a header row: "
                                 "add --no-header");
  }
  return {.gaps = io::GapPolicyFromString(gaps),
          .delimiter = io::DelimiterFromString(delimiter),
          .gaps_name = "--gaps",
          .names = columns,
          .skip_rows = skip_rows,
          .bad_lines = io::BadLinesFromString(bad_lines),
          .ulog = {.topic = ulog.topic,
                   .axes = ulog.axes,
                   .temperature = ulog.temperature,
                   .units = allan::RateUnitFromString(ulog_units)},
          .ulog_instance = ulog_instance};
}

void LogArgs::RequireOneRecord(std::string_view who, std::string_view why) const {
  if (gaps != "split" && gaps != "carry") return;
  throw UsageError(fmt::format("--gaps {}: {} needs one uniform record ({}): use --gaps "
                               "interpolate (the made-up rows then count as data) or --gaps error",
                               gaps, who, why));
}

void AddLogOptions(CLI::App* cmd, LogArgs* log) {
  cmd->add_option("--gaps", log->gaps,
                  "a time_s step of 1.5 median steps or more (missing samples): error (refuse, "
                  "naming the row) | interpolate (fill every column linearly; the made-up rows "
                  "count as data and are marked in the outputs) | split (keep the rows; the "
                  "thermal model's lag states restart after each gap) | carry (fill as "
                  "interpolate; the lag states run across the gaps, fits, scores and reports use "
                  "the logged rows only). docs/cli.md says what each command does with each")
      ->check(CLI::IsMember({"error", "interpolate", "split", "carry"}))
      ->capture_default_str();
  cmd->add_option("--delimiter", log->delimiter,
                  "cell delimiter: auto (a comma where the header has one, else a tab, else a "
                  "semicolon) | comma | tab | semicolon")
      ->check(CLI::IsMember({"auto", "comma", "tab", "semicolon"}))
      ->capture_default_str();
  cmd->add_flag("--no-header", log->no_header,
                "the file has no header row: --columns names its columns (a serial capture)");
  BindSetting(AddListOption(cmd, "--columns", &log->columns,
                            "with --no-header: the names of the file's columns, in order, "
                            "comma-separated (e.g. temp_c,ax,ay,az,gx,gy,gz)"),
              {"names"});
  cmd->add_option("--skip-rows", log->skip_rows,
                  "lines skipped at the start of the file, before the header or the first row "
                  "(a terminal program's banner); lines starting with # are skipped anyway")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--bad-lines", log->bad_lines,
                  "a row with another number of cells, or a cell that is not a number: error "
                  "(refuse, naming the line) | skip (leave it out; the note lists the lines)")
      ->check(CLI::IsMember({"error", "skip"}))
      ->capture_default_str();
  // A ULog is recognised by its first bytes; these choose what is read of it (as convert does).
  cmd->add_option("--ulog-topic", log->ulog.topic,
                  "a PX4 ULog log: the topic read (its time stamps, rate fields and temperature)")
      ->capture_default_str();
  BindSetting(cmd->add_option("--ulog-instance", log->ulog_instance,
                              "a PX4 ULog log: the topic's multi-instance id (convert --list "
                              "shows them)")
                  ->capture_default_str(),
              {"ulog_instance"});
  cmd->add_option("--ulog-units", log->ulog_units,
                  "a PX4 ULog log: unit of its rate columns <axis>_<units>: dph | dps | rads")
      ->check(CLI::IsMember({"dph", "dps", "rads"}))
      ->capture_default_str();
}

std::string MadeUpRowsPredictionNote(const std::vector<bool>& logged) {
  long made_up = 0, gaps = 0;
  for (size_t i = 0; i < logged.size(); ++i) {
    if (logged[i]) continue;
    ++made_up;
    gaps += i == 0 || logged[i - 1];
  }
  if (made_up == 0) return "";
  return fmt::format(
      "note: the predictions of the {} rows --gaps interpolate made up ({} gap{}), and the first "
      "after each gap, read the logged sample after the gap: they are not causal\n",
      made_up, gaps, gaps == 1 ? "" : "s");
}

io::CsvTable ReadLog(const std::string& path, const LogArgs& log, std::string* notes,
                     std::vector<Eigen::Index>* record_starts,
                     const std::vector<std::string>& columns, std::vector<bool>* logged) {
  std::string note;
  io::CsvTable table = io::ReadLog(path, log.Options(), &note, record_starts, columns, logged);
  if (!note.empty()) *notes += note + "\n";
  return table;
}

}  // namespace gyrodrift::cli
